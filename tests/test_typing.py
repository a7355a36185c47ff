"""The package is typed (PEP 561 ``py.typed``) and mypy-clean; its public API types the way an
OpenCV user writes code.  One mypy run (configuration: pyproject.toml [tool.mypy]; cache in
build/mypy_cache, a few seconds once warm).  Skipped when mypy is not installed, failed then
under ``MSTRACK_REQUIRE_TOOLS=1`` (make test): tools/setup.sh installs it (extra "test")."""
import importlib.util
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

USER_CODE = '''
import cv2
import numpy as np
import mstrack
from mstrack import Box, TrackResult, TrackerMeanShift, TrackerParams

frame = np.zeros((120, 160, 3), np.uint8)
trk = mstrack.Tracker(kernel="epan")
res: TrackResult = trk.init(frame, (10, 10, 20, 20))
x, y, w, h = res.box
total: float = x + y + w + h + res.box[0]
rect: tuple[int, int, int, int] = res.box.to_cv()
cv2.rectangle(frame, rect, (0, 255, 0), 2)
ok: bool = res.ok
conf: float = res.confidence
cvt = TrackerMeanShift.create(TrackerParams(preset="paper"))
cvt.init(frame, rect)
ok2, (rx, ry, rw, rh) = cvt.update(frame)
n: int = rx + ry + rw + rh
b: Box = Box.of([1, 2, 3, 4])
'''


def test_package_is_typed_and_mypy_clean(tmp_path):
    assert (ROOT / "mstrack" / "py.typed").is_file()
    if importlib.util.find_spec("mypy") is None:
        if os.environ.get("MSTRACK_REQUIRE_TOOLS", "") not in ("", "0"):
            pytest.fail("MSTRACK_REQUIRE_TOOLS is set and mypy is missing (tools/setup.sh, extra 'test')")
        pytest.skip("mypy not installed (tools/setup.sh installs it)")
    user = tmp_path / "user_code.py"
    user.write_text(textwrap.dedent(USER_CODE))
    r = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(ROOT / "build" / "mypy_cache"),
                        "mstrack", str(user)], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Success: no issues found" in r.stdout
