"""The CI tiers of tb/: tb/conftest.py's CI_EXTRA list (tests that run in `make test-extra` only)
must name tests that exist, and a parametrised block test listed by parameter keeps at least one
parameter set in `make test`."""
from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _ci_extra() -> dict[str, str]:
    spec = importlib.util.spec_from_file_location("tb_conftest", ROOT / "tb" / "conftest.py")
    assert spec and spec.loader
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.CI_EXTRA


def _collect(marks: str) -> list[str]:
    out = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider",
                          "-m", marks, "tb"], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    return [ln for ln in out.stdout.splitlines() if "::" in ln]


def test_ci_extra_entries_name_tests_and_leave_a_case_in_make_test():
    extra = _ci_extra()
    assert extra, "CI_EXTRA is empty"
    in_extra = _collect("extra")
    in_ci = _collect("not extra")
    for key, why in extra.items():
        assert why.strip(), f"{key}: say what covers it in make test"
        hits = [n for n in in_extra if n == key or n.split("[", 1)[0] == key]
        assert hits, f"CI_EXTRA entry {key} names no test (renamed or removed?)"
        assert not [n for n in in_ci if n == key or (n.split("[", 1)[0] == key and "[" not in key)], key
        if "[" in key:    # one parameter set moved: the test itself still runs in make test
            base = key.split("[", 1)[0]
            assert any(n.split("[", 1)[0] == base for n in in_ci), f"{base}: no parameter set left in make test"
