"""The project's files speak of the project as it is.

* No git-tracked file (code, tests, RTL, docs, CHANGELOG.md, data) contains the word that names a
  work period of its authors (``WORD`` below, matched case-insensitively, also inside other words):
  history goes to commit messages and the changelog's versions, not to files.
* README.md and docs/ (the prose pages) name no issue number, "(issue N" or "issue N", and no
  assistant of its authors (``ASSISTANT`` below): each page says what is true now, in the
  project's own terms.
* Every ``tools/...`` or ``studies/...`` script that a tracked text file names exists, so the
  commands the docs give can be run (tools/ holds the tools the build uses; studies/ the scripts
  that regenerate a docs table, studies/README.md).

The file list is ``git ls-files`` of the repository (the test skips outside a git checkout).
"""
from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
#: the forbidden word, assembled so that this file does not contain it
WORD = "ses" + "sion"
#: the word for an assistant of the authors, assembled so that this file does not contain it
ASSISTANT = "hel" + "per"
#: prose pages checked for issue numbers and ASSISTANT
PROSE_GLOBS = ("README.md", "docs/*.md", "docs/blocks/*.md")
#: text files whose script references must resolve
TEXT_SUFFIXES = {".md", ".py", ".toml", ".txt", ".sh", ".vhd", ".core", ".yml", ".yaml", ""}
SCRIPT_REF = re.compile(r"(?<![\w./-])((?:tools|studies)/[\w./-]*\w\.(?:py|sh))\b")
ISSUE_REF = re.compile(r"\(issue\b|\bissues?\s+\d", re.IGNORECASE)
ASSISTANT_REF = re.compile(ASSISTANT, re.IGNORECASE)


def tracked_files() -> list[Path]:
    if shutil.which("git") is None or not (REPO / ".git").exists():
        pytest.skip("not a git checkout (the word checks run on git-tracked files)")
    out = subprocess.run(["git", "-C", str(REPO), "ls-files", "-z"], capture_output=True, check=True).stdout
    return [REPO / p for p in out.decode().split("\0") if p and (REPO / p).is_file()]


def _hits(pattern: re.Pattern[str], text: str) -> list[str]:
    """'line N: <line>' for every line of text that matches pattern."""
    return [f"line {n}: {line.strip()[:120]}" for n, line in enumerate(text.splitlines(), 1)
            if pattern.search(line)]


def test_no_tracked_file_names_a_work_period():
    word = re.compile(re.escape(WORD), re.IGNORECASE)
    bad = {}
    for path in tracked_files():
        data = path.read_bytes()
        if WORD.encode() not in data.lower():
            continue
        text = data.decode("utf-8", errors="replace")
        bad[str(path.relative_to(REPO))] = _hits(word, text)[:3] or ["(in binary content)"]
    assert not bad, (f"{len(bad)} tracked file(s) contain '{WORD}' (write what is true now; history "
                     f"goes to commit messages): " + "; ".join(f"{p}: {h}" for p, h in sorted(bad.items())))


def test_prose_names_no_issue_numbers_or_assistants():
    files = sorted({p for g in PROSE_GLOBS for p in REPO.glob(g)})
    assert files, "no README.md or docs/*.md found"
    bad = {}
    for path in files:
        text = path.read_text()
        hits = _hits(ISSUE_REF, text) + _hits(ASSISTANT_REF, text)
        if hits:
            bad[str(path.relative_to(REPO))] = hits[:3]
    assert not bad, f"issue numbers or '{ASSISTANT}' in the docs: " + "; ".join(
        f"{p}: {h}" for p, h in sorted(bad.items()))


def test_named_tools_and_studies_exist():
    missing = {}
    for path in tracked_files():
        if path.suffix not in TEXT_SUFFIXES:
            continue
        try:
            text = path.read_text()
        except UnicodeDecodeError:
            continue
        for ref in SCRIPT_REF.findall(text):
            if not (REPO / ref).is_file():
                missing.setdefault(ref, str(path.relative_to(REPO)))
    assert not missing, "scripts named but not in the repository: " + "; ".join(
        f"{ref} (named in {where})" for ref, where in sorted(missing.items()))


def test_patterns_catch_what_they_should():
    """The checks themselves: each pattern matches its example and leaves the legitimate uses."""
    assert ISSUE_REF.search("done (issue 11)") and ISSUE_REF.search("Issue 10's target")
    assert not ISSUE_REF.search("GHDL issue #2041") and not ISSUE_REF.search("issue + division")
    assert ASSISTANT_REF.search(f"a {ASSISTANT.title()} run")
    assert SCRIPT_REF.findall("run `python studies/v2_mean.py --md`, then tools/setup.sh") == [
        "studies/v2_mean.py", "tools/setup.sh"]
    assert SCRIPT_REF.findall("mstrack/tools/x.py") == []
