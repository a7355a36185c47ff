"""The release: `python -m build` gives an sdist and a wheel, and the wheel works in a fresh venv.

``test_wheel_in_fresh_venv`` (`make test-extra`, marker ``extra``): the wheel is installed, with its
dependencies pinned by requirements.lock and fetched by pip, into a new virtual environment that shares
nothing with the project's.  ``test_wheel_in_new_venv_with_the_locked_dependencies`` (`make test`): the
wheel alone (``--no-deps``) in a new virtual environment that sees the project's installed dependencies
(the versions requirements.lock pins) through a path file; there every requirement of the wheel must be
installed at a version it allows.  In both, ``mstrack --version`` must print the package version of pyproject.toml and the
tool line, and ``mstrack track`` must track a short generated video to its last frame.  CHANGELOG.md must
have a section for that version.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def _version() -> str:
    return str(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"])


def _source_copy(dst: Path) -> Path:
    """The files a build reads (pyproject, README, the package), so that the build writes nothing
    into the checkout (build/, *.egg-info) while other tests run."""
    src = dst / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, src / name)
    shutil.copytree(ROOT / "mstrack", src / "mstrack", ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return src


def _run(cmd: list[str], timeout: float, **kw: object) -> subprocess.CompletedProcess[str]:
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)  # type: ignore[call-overload]
    assert r.returncode == 0, f"{' '.join(map(str, cmd))} failed ({r.returncode}):\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return r


def test_changelog_has_the_version() -> None:
    text = (ROOT / "CHANGELOG.md").read_text()
    v = _version()
    assert re.search(rf"^## \[{re.escape(v)}\] - \d{{4}}-\d{{2}}-\d{{2}}$", text, re.M), \
        f"CHANGELOG.md has no '## [{v}] - YYYY-MM-DD' section"
    # Keep a Changelog: the newest version first, an Unreleased section above it
    versions = re.findall(r"^## \[([^\]]+)\]", text, re.M)
    assert versions[0] == "Unreleased" and versions[1] == v, versions[:3]


@pytest.fixture(scope="module")
def dist(tmp_path_factory: pytest.TempPathFactory) -> Path:
    pytest.importorskip("build", reason="the 'build' package (extra 'test') is needed to build the sdist and wheel")
    tmp = tmp_path_factory.mktemp("release")
    src = _source_copy(tmp)
    out = tmp / "dist"
    # an isolated build, its back end (setuptools) pinned by requirements.lock as in tools/setup.sh
    env = {**os.environ, "PIP_CONSTRAINT": str(ROOT / "requirements.lock")}
    _run([sys.executable, "-m", "build", "--sdist", "--wheel", "--outdir", str(out), str(src)], timeout=600, env=env)
    return out


def test_build_gives_sdist_and_wheel(dist: Path) -> None:
    v = _version()
    wheels = sorted(dist.glob(f"mstrack-{v}-*.whl"))
    sdists = sorted(dist.glob(f"mstrack-{v}.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1, sorted(p.name for p in dist.iterdir())
    names = set(zipfile.ZipFile(wheels[0]).namelist())
    for must in ("mstrack/__init__.py", "mstrack/py.typed", "mstrack/cli.py", "mstrack/fixed/tracker_v2.py",
                 "mstrack/track/float_v2.py", f"mstrack-{v}.dist-info/entry_points.txt"):
        assert must in names, f"{must} missing from {wheels[0].name}"
    with tarfile.open(sdists[0]) as tf:
        members = {m.name.split("/", 1)[1] for m in tf.getmembers() if "/" in m.name}
    assert {"pyproject.toml", "README.md", "mstrack/__init__.py"} <= members


def _video(path: Path, n: int = 12) -> tuple[int, int, int, int]:
    """A short AVI: a red square moving right on a textured background; returns its first box."""
    import cv2
    rng = np.random.default_rng(7)
    bg = rng.integers(0, 80, (120, 160, 3), dtype=np.uint8)
    vw = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 15.0, (160, 120))
    assert vw.isOpened(), "OpenCV cannot write an MJPG AVI here"
    for i in range(n):
        f = bg.copy()
        f[40:70, 30 + 3 * i:60 + 3 * i] = (30, 40, 220)
        vw.write(f)
    vw.release()
    return 30, 40, 30, 30


def _new_venv(tmp_path: Path) -> tuple[Path, Path, dict[str, str]]:
    """A new virtual environment under *tmp_path*: (its dir, its python, an environment without this one's)."""
    venv = tmp_path / "venv"
    _run([sys.executable, "-m", "venv", str(venv)], timeout=120)
    env = {k: val for k, val in os.environ.items() if not k.startswith(("PYTHON", "VIRTUAL_ENV"))}
    return venv, venv / "bin" / "python", env


@pytest.mark.extra
def test_wheel_in_fresh_venv(dist: Path, tmp_path: Path) -> None:
    venv, py, env = _new_venv(tmp_path)
    env["PIP_CONSTRAINT"] = str(ROOT / "requirements.lock")  # what CI tested is what gets installed
    _run([str(py), "-m", "pip", "install", "-q", str(next(dist.glob("mstrack-*.whl")))], timeout=900, env=env)
    _check_installed(venv, tmp_path, env)


def test_wheel_in_new_venv_with_the_locked_dependencies(dist: Path, tmp_path: Path) -> None:
    venv, py, env = _new_venv(tmp_path)
    _run([str(py), "-m", "pip", "install", "-q", "--no-deps", str(next(dist.glob("mstrack-*.whl")))],
         timeout=300, env=env)
    # the dependencies: this interpreter's site-packages (installed from requirements.lock), after the new
    # venv's own (a path file adds a directory only: the checkout's editable install stays out)
    own = _run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], timeout=60,
               env=env).stdout.strip()
    (Path(own) / "zz_locked_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _run([str(py), "-c", _REQUIREMENTS_MET], timeout=120, env=env, cwd=tmp_path)
    _check_installed(venv, tmp_path, env)


#: run in the new venv: every requirement of the installed wheel (no extras) is installed at a version it allows
_REQUIREMENTS_MET = """
import sys
from importlib.metadata import PackageNotFoundError, distribution, version
from packaging.requirements import Requirement
d = distribution("mstrack")
assert str(d.locate_file("")).startswith(sys.prefix), d.locate_file("")
bad = []
for text in d.requires or []:
    r = Requirement(text)
    if r.marker is not None and not r.marker.evaluate({"extra": ""}):
        continue
    try:
        v = version(r.name)
    except PackageNotFoundError:
        bad.append(f"{r}: not installed")
        continue
    if not r.specifier.contains(v, prereleases=True):
        bad.append(f"{r}: {v} installed")
assert d.requires and not bad, bad
"""


def _check_installed(venv: Path, tmp_path: Path, env: dict[str, str]) -> None:
    py = venv / "bin" / "python"
    # the installed package is the wheel's, not this checkout's
    where = _run([str(py), "-c", "import mstrack, sys; print(mstrack.__file__)"], timeout=60, env=env,
                 cwd=tmp_path).stdout.strip()
    assert where.startswith(str(venv)), where
    mstrack = venv / "bin" / "mstrack"
    out = _run([str(mstrack), "--version"], timeout=120, env=env, cwd=tmp_path).stdout.splitlines()
    assert out[0] == f"mstrack {_version()}", out
    assert out[1].startswith("Tools: numpy ") and "OpenCV" in out[1], out
    box = _video(tmp_path / "clip.avi")
    _run([str(mstrack), "track", str(tmp_path / "clip.avi"), "--box", ",".join(map(str, box)),
          "--out", str(tmp_path / "trk"), "--quiet"], timeout=600, env=env, cwd=tmp_path)
    res = json.loads((tmp_path / "trk" / "results.json").read_text())
    assert res["frames"] == 12 and len(res["frames_data"]) == 12, res["frames"]
    last = res["frames_data"][-1]
    assert abs(float(last["x"]) - (30 + 3 * 11)) < 6, last  # it followed the square
