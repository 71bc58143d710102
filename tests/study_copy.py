"""Copies of the repository's study folders for tests that need a studies folder of their own."""

from pathlib import Path

REPO_STUDIES = Path(__file__).resolve().parents[1] / "studies"


def copy_study_folder(name: str, root: Path, edit=None, src: Path = REPO_STUDIES) -> Path:
    """Copy the study folder ``name`` (study.toml and code, not its outputs) and the shared conventions.toml into the
    studies folder ``root``; ``edit(text) -> text`` changes the copy's study.toml. Returns the copied folder."""
    import shutil

    root.mkdir(parents=True, exist_ok=True)
    shutil.copytree(
        src / name, root / name, ignore=shutil.ignore_patterns("out", "data", "__pycache__"), dirs_exist_ok=True
    )
    if not (root / "conventions.toml").exists():
        shutil.copy(src / "conventions.toml", root / "conventions.toml")
    if edit is not None:
        toml = root / name / "study.toml"
        text = toml.read_text()
        new = edit(text)
        assert new != text, "the edit did not apply"
        toml.write_text(new)
    return root / name
