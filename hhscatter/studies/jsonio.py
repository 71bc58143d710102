"""The numbers JSON of a study, written atomically: non-finite floats as null/"inf", numpy scalars as Python, a
:class:`~hhscatter.analysis.stats.measured.Measured` as its ``.to_dict()``."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

from hhscatter.analysis.stats.measured import Measured

__all__ = ["write_json_atomic"]


def _jsonable(v):
    if isinstance(v, Measured):
        return _jsonable(v.to_dict())
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if hasattr(v, "item") and callable(v.item) and getattr(v, "ndim", 1) == 0:
        return _jsonable(v.item())
    if hasattr(v, "tolist"):
        return _jsonable(v.tolist())
    return v


def write_json_atomic(path: Path, obj) -> None:
    """Write ``obj`` as indented JSON to ``path`` via a temporary file and rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text(json.dumps(_jsonable(obj), indent=2, sort_keys=False, allow_nan=False) + "\n")
    os.replace(tmp, path)
