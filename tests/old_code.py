"""The package as an earlier commit had it, for tests that compare today's output with the code before a change."""

import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def code_at(commit: str, dest: Path, paths=("hhscatter",)) -> Path:
    """Extract ``paths`` of ``commit`` into ``dest`` (made here) and return it; skip the test, saying why, where git or
    that commit is not available (a shallow clone)."""
    if (
        shutil.which("git") is None
        or subprocess.run(["git", "cat-file", "-e", commit], cwd=REPO, capture_output=True).returncode != 0
    ):
        pytest.skip(f"needs the git history with {commit}")
    dest.mkdir(parents=True)
    archive = subprocess.run(["git", "archive", commit, *paths], cwd=REPO, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
    return dest
