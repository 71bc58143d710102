"""Checks of the geometry estimators' arguments (extents, point sets, whole numbers), run before any work.

>>> extent((-1, 1, -1, 1))
(-1.0, 1.0, -1.0, 1.0)
>>> points([[0.0, 1.0]], "P").shape
(1, 2)
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError


def extent(e, name: str = "extent") -> tuple[float, float, float, float]:
    """``e`` as (x0, x1, y0, y1), four finite numbers with x0 < x1 and y0 < y1 (position units)."""
    v = check.numbers(e, name)
    if v.size != 4 or not (v[1] > v[0] and v[3] > v[2]):
        raise ConfigError(f"{name} must be (x0, x1, y0, y1) with x0 < x1 and y0 < y1, got {e!r}")
    return tuple(float(x) for x in v)


def points(X, name: str, *, min_size: int = 1) -> np.ndarray:
    """``X`` as an (n, 2) float array of finite points, n ≥ ``min_size``."""
    if isinstance(X, (str, bytes, dict)) or X is None:
        raise ConfigError(f"{name} must be an (n, 2) array of points, got {type(X).__name__}")
    try:
        a = np.asarray(X)
    except (TypeError, ValueError):
        a = np.asarray(None)
    if a.dtype == bool or a.dtype.kind not in "iuf":
        raise ConfigError(f"{name} must be an (n, 2) array of points, got {type(X).__name__}")
    a = a.astype(float)
    if a.ndim != 2 or a.shape[1] != 2:
        raise ConfigError(f"{name} must be an (n, 2) array of points, got shape {a.shape}")
    if a.shape[0] < min_size:
        raise ConfigError(f"{name} must hold at least {min_size} point(s), got {a.shape[0]}")
    if not np.all(np.isfinite(a)):
        raise ConfigError(f"{name} must be finite (no NaN or inf)")
    return a


def whole(v, name: str, minimum: int = 1) -> int:
    """``v`` as an int ≥ ``minimum``: an integer or a whole-valued float, not a bool."""
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v):
        raise ConfigError(f"{name} must be an integer ≥ {minimum}, got {v!r}")
    if not float(v).is_integer() or int(v) < minimum:
        raise ConfigError(f"{name} must be an integer ≥ {minimum}, got {v!r}")
    return int(v)


def values(a, name: str, *, size: int | None = None, min_size: int = 1) -> np.ndarray:
    """``a`` as a 1-D float array in which NaN and inf are allowed (a value not measured); ``size`` values if given."""
    if isinstance(a, (str, bytes, dict)) or a is None:
        raise ConfigError(f"{name} must be an array of numbers, got {type(a).__name__}")
    try:
        arr = np.asarray(a)
    except (TypeError, ValueError):
        arr = np.asarray(None)
    if arr.dtype == bool or arr.dtype.kind not in "iuf":
        raise ConfigError(f"{name} must be an array of numbers, got {type(a).__name__}")
    arr = arr.astype(float).ravel()
    if size is not None and arr.size != size:
        raise ConfigError(f"{name} must hold {size} value(s), one per energy, got {arr.size}")
    if arr.size < min_size:
        raise ConfigError(f"{name} must hold at least {min_size} value(s), got {arr.size}")
    return arr


def mapping(m, name: str, keys=()) -> dict:
    """``m`` if it is a mapping holding ``keys`` (a result or record of another estimator)."""
    if not isinstance(m, Mapping):
        raise ConfigError(f"{name} must be a mapping (a result or record), got {type(m).__name__}")
    missing = [k for k in keys if k not in m]
    if missing:
        raise ConfigError(f"{name} lacks the keys {missing}")
    return m


def wholes(a, name: str, minimum: int = 1) -> list[int]:
    """``a`` as a non-empty list of ints ≥ ``minimum`` (integers or whole-valued floats)."""
    return [whole(v, name, minimum) for v in check.numbers(a, name)]


def potential(model, name: str = "model"):
    """``model`` if it has a potential V(x, y) to call (a system)."""
    if not callable(getattr(model, "potential", None)):
        raise ConfigError(f"{name} must be a system with a potential V(x, y), got {type(model).__name__}")
    return model


def reference(ref, name: str):
    """``ref`` if it is None or (value, err), two numbers (NaN allowed: not measured)."""
    if ref is None:
        return ref
    if isinstance(ref, (str, bytes, dict)) or not hasattr(ref, "__len__") or len(ref) != 2:
        raise ConfigError(f"{name} must be (value, err) or None, got {ref!r}")
    if any(isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) for v in ref):
        raise ConfigError(f"{name} must be (value, err), two numbers (NaN: not measured), got {ref!r}")
    return ref


def generator(rng, name: str = "rng"):
    """``rng`` if it is a :class:`numpy.random.Generator`."""
    if not isinstance(rng, np.random.Generator):
        raise ConfigError(f"{name} must be a numpy.random.Generator, got {type(rng).__name__}")
    return rng
