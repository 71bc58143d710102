"""Print pip constraints pinning every dependency to the lowest version pyproject.toml allows.

``make test-min`` installs hhscatter with these constraints into ``.venv-min``
and runs the test suite there, so the floors in pyproject.toml are tested
rather than guessed. Usage: ``python tools/min_requirements.py [EXTRA ...]``
(default extras: dev bench). Every requirement must have a ``>=`` floor.
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REQ = re.compile(r"^\s*([A-Za-z0-9_.-]+)(\[[^\]]*\])?\s*(.*)$")


def floors(requirements) -> dict[str, str]:
    """floors(['numpy>=1.24', 'dask[distributed]>=2024.1', …]) -> {'numpy': '1.24', 'dask': '2024.1', …}."""
    out = {}
    for req in requirements:
        name, _, spec = REQ.match(req).groups()
        low = [v for op, v in re.findall(r"(>=|==)\s*([^,;\s]+)", spec)]
        if not low:
            raise SystemExit(f"{req!r} has no lower bound (>=): every dependency needs a tested floor")
        out[name.lower()] = low[0]
    return out


def main(argv=None) -> int:
    extras = (argv if argv is not None else sys.argv[1:]) or ["dev", "bench"]
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    reqs = list(project["dependencies"])
    for extra in extras:
        reqs += project["optional-dependencies"][extra]
    for name, version in sorted(floors(reqs).items()):
        print(f"{name}=={version}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
