"""Execute a notebook in a fresh temporary folder and store its outputs in place (``make tutorial``).

    python tools/execute_notebook.py docs/tutorial.ipynb [--check]

The notebook's runs (``runs/…`` relative paths) go to the temporary folder, which is removed afterwards.
Execution timestamps are dropped, so that re-running changes the file only where an output changed.
``--check`` executes without writing (what tests/docs/test_tutorial.py does). Exit 1 if a cell fails.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path


def execute(path: Path, cwd: Path, timeout: int = 600):
    """execute(path, cwd, timeout=600) -> the executed notebook (nbformat node); raises CellExecutionError."""
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=timeout, kernel_name="python3", resources={"metadata": {"path": str(cwd)}}).execute()
    for cell in nb.cells:
        cell.metadata.pop("execution", None)
    return nb


def main(argv=None) -> int:
    import nbformat

    args = list(sys.argv[1:] if argv is None else argv)
    check = "--check" in args
    path = Path(next(a for a in args if a != "--check")).resolve()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        nb = execute(path, Path(tmp))
    if not check:
        nbformat.write(nb, path)
    print(f"{path.name}: executed in {time.perf_counter() - t0:.0f} s" + ("" if check else ", outputs stored"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
