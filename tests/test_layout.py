"""The package layout and its import rule (README.md and docs/architecture.md, "Package layout").

Every module of ``mstrack/`` is parsed with :mod:`ast` (nothing is imported) and each import,
relative or absolute, at module level or inside a function, is resolved to the mstrack module it
names.  The layers and what each may import::

    track  (mstrack/track/)   -> track; fixed only inside a function (Tracker(model="fixed"))
    fixed  (mstrack/fixed/)   -> fixed, track
    io     (mstrack/io/)      -> io, track
    util   (mstrack/versions) -> nothing of mstrack
    eval   (mstrack/eval/)    -> eval, io, track, fixed, util
    hw     (mstrack/hw/)      -> hw, io, track, fixed, util
    app    (mstrack/__init__, mstrack/cli and any other top-level module) -> anything

and no module outside the app layer imports an app module.  So cli -> eval, hw -> track/fixed,
and neither eval nor hw (nor anything below them) imports the other or the CLI.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "mstrack"

SUBPACKAGES = {"track", "fixed", "io", "eval", "hw"}
UTIL = {"mstrack.versions"}
ALLOWED = {  # layer -> layers it may import (at module level; "track" may also import fixed lazily)
    "track": {"track"},
    "fixed": {"fixed", "track"},
    "io": {"io", "track"},
    "util": set(),
    "eval": {"eval", "io", "track", "fixed", "util"},
    "hw": {"hw", "io", "track", "fixed", "util"},
    "app": {"track", "fixed", "io", "util", "eval", "hw", "app"},
}
LAZY_ALLOWED = {"track": {"fixed"}}  # imports inside a function only


def module_name(path: Path, root: Path = PKG) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def layer(mod: str) -> str:
    parts = mod.split(".")
    if len(parts) >= 2 and parts[1] in SUBPACKAGES:
        return parts[1]
    if mod in UTIL:
        return "util"
    return "app"  # mstrack, mstrack.cli and any other top-level module


def _is_module(mod: str, root: Path) -> bool:
    rel = Path(*mod.split(".")[1:]) if "." in mod else Path()
    base = root / rel
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


def imports(source: str, mod: str, is_pkg: bool, root: Path = PKG) -> list[tuple[str, int, bool]]:
    """``(imported mstrack module, line, inside a function)`` for every import in ``source``."""
    tree = ast.parse(source)
    package = mod if is_pkg else mod.rpartition(".")[0]
    out: list[tuple[str, int, bool]] = []

    def visit(node: ast.AST, lazy: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inner = lazy or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.Import):
                out.extend((a.name, child.lineno, lazy) for a in child.names
                           if a.name == "mstrack" or a.name.startswith("mstrack."))
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = package.split(".")
                    base = base[:len(base) - (child.level - 1)]
                    target = ".".join(base + ([child.module] if child.module else []))
                else:
                    target = child.module or ""
                if target != "mstrack" and not target.startswith("mstrack."):
                    continue
                subs = [f"{target}.{a.name}" for a in child.names if _is_module(f"{target}.{a.name}", root)]
                out.extend((s, child.lineno, lazy) for s in subs)
                if len(subs) < len(child.names):
                    out.append((target, child.lineno, lazy))
            visit(child, inner)

    visit(tree, False)
    return out


def violations(root: Path = PKG) -> list[str]:
    bad = []
    for path in sorted(root.rglob("*.py")):
        mod = module_name(path, root)
        src_layer = layer(mod)
        for target, line, lazy in imports(path.read_text(), mod, path.name == "__init__.py", root):
            if target == "mstrack" and src_layer != "app":
                bad.append(f"{path.relative_to(root.parent)}:{line}: imports the package root mstrack")
                continue
            dst_layer = layer(target)
            ok = dst_layer in ALLOWED[src_layer] or (lazy and dst_layer in LAZY_ALLOWED.get(src_layer, set()))
            if not ok:
                how = "inside a function" if lazy else "at module level"
                bad.append(f"{path.relative_to(root.parent)}:{line}: {src_layer} module {mod} imports "
                           f"{target} ({dst_layer}) {how}")
    return bad


def test_import_rule_holds():
    bad = violations()
    assert not bad, "imports against the layer rule:\n" + "\n".join(bad)


def test_subpackages_are_the_layers():
    """A new subpackage needs a place in the rule above before it can hold code."""
    found = {p.parent.name for p in PKG.glob("*/__init__.py")}
    assert found == SUBPACKAGES


def test_every_module_of_the_layout_exists():
    """The modules the docs' layout tree names (a move that forgets one fails here)."""
    for mod in ("track.params", "track.types", "track.frames", "track.tracker", "track.float_model",
                "track.features", "track.kernel", "track.area", "track.numba_kernels", "track.float_v2",
                "track.features_v2", "fixed.tracker", "io.data", "io.synthetic", "eval.metrics",
                "eval.evaluate", "eval.report", "eval.baselines", "eval.agreement", "hw.hdl",
                "hw.hdl_config", "hw.cosim", "hw.fastsim", "hw.synth", "hw.regs", "hw.packaging",
                "hw.tb_files", "hw.vectors", "cli", "versions"):
        assert _is_module(f"mstrack.{mod}", PKG), mod


def test_dotted_names_in_code_resolve():
    """Strings in code that name an mstrack module (``"mstrack.hw.synth:register_cli"``, patch
    targets) name one that exists."""
    bad = []
    for path in sorted(PKG.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                s = node.value.split(":")[0]
                if (s.startswith("mstrack.") and s.replace(".", "").replace("_", "").isalnum()
                        and not (PKG.parent / s).is_file()):  # mstrack.core: the FuseSoC core file
                    parts = s.split(".")
                    # the longest prefix that is a module; an attribute may follow it
                    if not any(_is_module(".".join(parts[:i]), PKG) for i in range(2, len(parts) + 1)):
                        bad.append(f"{path.relative_to(PKG.parent)}:{node.lineno}: {node.value!r}")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("where, source, expect", [
    ("track/x.py", "from ..hw import hdl\n", "track module mstrack.track.x imports mstrack.hw.hdl (hw)"),
    ("track/x.py", "from ..fixed import tracker\n", "imports mstrack.fixed.tracker (fixed) at module level"),
    ("track/x.py", "def f():\n    from ..fixed import tracker\n", None),
    ("track/x.py", "def f():\n    from ..eval import metrics\n", "(eval) inside a function"),
    ("eval/x.py", "import mstrack.hw.synth\n", "eval module mstrack.eval.x imports mstrack.hw.synth (hw)"),
    ("eval/x.py", "from .. import cli\n", "imports mstrack.cli (app)"),
    ("hw/x.py", "from mstrack.eval.metrics import score\n", "imports mstrack.eval.metrics (eval)"),
    ("hw/x.py", "from ..io.data import load_sequence\nfrom ..versions import tools_line\n", None),
    ("io/x.py", "from ..versions import tools_line\n", "imports mstrack.versions (util)"),
    ("versions.py", "from .hw.hdl import verilator_root\n", "util module mstrack.versions imports"),
    ("fixed/x.py", "from .. import track\n", None),
    ("fixed/x.py", "from ..eval import report\n", "fixed module mstrack.fixed.x imports mstrack.eval.report"),
    ("cli.py", "from .eval import report\nfrom .hw import synth\n", None),
])
def test_the_rule_catches_violations(tmp_path, where, source, expect):
    """The checker on a scratch copy of the layout with one extra module: it can fail."""
    root = tmp_path / "mstrack"
    for sub in SUBPACKAGES:
        (root / sub).mkdir(parents=True)
        (root / sub / "__init__.py").write_text("")
        (root / sub / "_placeholder.py").write_text("")
    (root / "__init__.py").write_text("")
    for name in ("cli", "versions", "hw/hdl", "hw/synth", "fixed/tracker", "eval/metrics", "eval/report",
                 "io/data"):
        (root / f"{name}.py").write_text("")
    (root / where).write_text(source)
    bad = violations(root)
    if expect is None:
        assert bad == []
    else:
        assert len(bad) == 1 and expect in bad[0], bad
