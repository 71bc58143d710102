"""How many worker processes a run uses by default: the CPUs this process may run on."""
from __future__ import annotations

import os

__all__ = ["default_workers"]


def default_workers() -> int:
    """default_workers() -> the number of CPUs this process may use (its affinity mask), at least 1."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)
