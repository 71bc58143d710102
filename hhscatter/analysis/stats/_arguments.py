"""Checks of an estimator's arguments, run before any work: each refuses with a ConfigError naming the argument.

>>> numbers([1.0, 2.0], "t_end").tolist()
[1.0, 2.0]
>>> numbers([1.0, float("nan")], "t_end")
Traceback (most recent call last):
...
hhscatter.errors.ConfigError: t_end must be finite (no NaN or inf)
>>> import pandas as pd
>>> table(pd.DataFrame({"t_end": [1.0]}), "lifetimes", ["t_end", "outcome"])
Traceback (most recent call last):
...
hhscatter.errors.ConfigError: lifetimes lacks the column(s) outcome; it has t_end
>>> mapping([], "fits")
Traceback (most recent call last):
...
hhscatter.errors.ConfigError: fits must be a dict, got list
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from hhscatter.errors import ConfigError


def _float_array(a, name: str) -> np.ndarray:
    """``a`` as a flat float array of numbers (NaN and inf kept); a word, a mapping, None or booleans refused."""
    if isinstance(a, (str, bytes, dict)) or a is None:
        raise ConfigError(f"{name} must be an array of numbers, got {type(a).__name__}")
    try:
        arr = np.asarray(a)
        if arr.dtype == bool or arr.dtype.kind not in "iuf":
            raise TypeError
        arr = arr.astype(float).ravel()
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be an array of numbers, got {type(a).__name__}") from None
    return arr


def numbers(
    a, name: str, *, min_size: int = 1, minimum: float | None = None, positive: bool = False, flat: bool = False
) -> np.ndarray:
    """``a`` as a 1-D float array of finite numbers (at least ``min_size``; ≥ ``minimum``, or > 0 if ``positive``);
    ``flat``: ``a`` itself must be one-dimensional (a nesting or a single number refused, not flattened)."""
    if flat:
        try:
            one_d = np.ndim(a) == 1
        except ValueError:  # a ragged nesting
            one_d = False
        if not one_d:
            raise ConfigError(f"{name} must be a 1-D array of numbers, got {type(a).__name__}")
    arr = _float_array(a, name)
    if arr.size < min_size:
        raise ConfigError(f"{name} must hold at least {min_size} value(s), got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name} must be finite (no NaN or inf)")
    if positive and not np.all(arr > 0):
        raise ConfigError(f"{name} must be > 0")
    if minimum is not None and not np.all(arr >= minimum):
        raise ConfigError(f"{name} must be ≥ {minimum:g}")
    return arr


def mask(a, name: str, size: int) -> np.ndarray:
    """``a`` as a 1-D boolean array of ``size`` values (booleans, or 0/1)."""
    if isinstance(a, (str, bytes, dict)) or a is None:
        raise ConfigError(f"{name} must be a boolean mask, got {type(a).__name__}")
    arr = np.asarray(a).ravel()
    if arr.dtype != bool:
        if arr.dtype.kind not in "iuf" or not np.all(np.isin(arr, (0, 1))):
            raise ConfigError(f"{name} must be a boolean mask (True/False or 1/0)")
        arr = arr.astype(bool)
    if arr.size != size:
        raise ConfigError(f"{name} must have one value per orbit: {arr.size} != {size}")
    return arr


def number(v, name: str, *, minimum: float | None = None, positive: bool = False) -> float:
    """``v`` as a finite float (≥ ``minimum``, or > 0 if ``positive``)."""
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v):
        raise ConfigError(f"{name} must be a finite number, got {v!r}")
    if positive and not v > 0:
        raise ConfigError(f"{name} must be > 0, got {v!r}")
    if minimum is not None and not v >= minimum:
        raise ConfigError(f"{name} must be ≥ {minimum:g}, got {v!r}")
    return float(v)


def count(v, name: str, minimum: int) -> int:
    """``v`` as an int ≥ ``minimum`` (an integer, not a bool or a float)."""
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < minimum:
        raise ConfigError(f"{name} must be an integer ≥ {minimum}, got {v!r}")
    return int(v)


def window(t_start, t_stop, names: tuple[str, str] = ("t_start", "t_stop")) -> tuple[float, float]:
    """(t_start, t_stop) as finite times with 0 ≤ t_start < t_stop."""
    a, b = number(t_start, names[0], minimum=0.0), number(t_stop, names[1])
    if not a < b:
        raise ConfigError(f"{names[0]} < {names[1]} is needed, got {a!r} and {b!r}")
    return a, b


def function(f, name: str) -> Callable:
    """``f`` if it can be called."""
    if not callable(f):
        raise ConfigError(f"{name} must be a function, got {type(f).__name__}")
    return f


def system(model, name: str = "model"):
    """``model`` if it is a :class:`~hhscatter.model.base.System`."""
    from hhscatter.model.base import System  # deferred: the model loads only for the estimators that take one

    if not isinstance(model, System):
        raise ConfigError(f"{name} must be a System (hhscatter.model), got {type(model).__name__}")
    return model


def table(df, name: str, columns=(), *, min_rows: int = 1):
    """``df`` if it is a DataFrame holding ``columns`` (the missing ones are named) and at least ``min_rows`` rows.

    >>> import pandas as pd
    >>> table(pd.DataFrame({"t": [1.0]}), "sections", ("traj_id", "t"))
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: sections lacks the column(s) traj_id; it has t
    """
    import pandas as pd  # deferred: pandas loads only for the estimators that take a table

    if not isinstance(df, pd.DataFrame):
        raise ConfigError(f"{name} must be a pandas DataFrame, got {type(df).__name__}")
    missing = [c for c in columns if c not in df.columns]
    if missing:
        have = ", ".join(map(str, df.columns)) or "no column"
        raise ConfigError(f"{name} lacks the column(s) {', '.join(missing)}; it has {have}")
    if len(df) < min_rows:
        raise ConfigError(f"{name} must hold at least {min_rows} row(s), got {len(df)}")
    return df


def curve(t, P, names: tuple[str, str] = ("t", "P")) -> tuple[np.ndarray, np.ndarray]:
    """A measured curve: increasing finite times ``t`` (at least one) and P with one value per time (NaN may stand)."""
    if np.ndim(t) != 1:
        raise ConfigError(f"{names[0]} must be a 1-D array of times, got {type(t).__name__}")
    t = numbers(t, names[0])
    P = floats(P, names[1], size=t.size, of=f"time {names[0]}")
    if np.any(np.diff(t) < 0):
        raise ConfigError(f"{names[0]} must be increasing")
    return t, P


def mapping(d, name: str, *, min_size: int = 0) -> dict:
    """``d`` if it is a mapping (a dict) of at least ``min_size`` entries."""
    if not isinstance(d, dict):
        raise ConfigError(f"{name} must be a dict, got {type(d).__name__}")
    if len(d) < min_size:
        raise ConfigError(f"{name} must hold at least {min_size} entr{'y' if min_size == 1 else 'ies'}, got {len(d)}")
    return d


def instance(obj, name: str, kind: type | tuple[type, ...]):
    """``obj`` if it is an instance of ``kind`` (a class, or a tuple of classes)."""
    if not isinstance(obj, kind):
        want = " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))
        raise ConfigError(f"{name} must be a {want}, got {type(obj).__name__}")
    return obj


def floats(a, name: str, *, size: int | None = None, of: str = "orbit") -> np.ndarray:
    """``a`` as a 1-D float array of numbers where NaN and inf may stand (the estimator drops them); ``size`` values."""
    arr = _float_array(a, name)
    if size is not None and arr.size != size:
        raise ConfigError(f"{name} must have one value per {of}: {arr.size} != {size}")
    return arr


def interval(w, name: str, *, minimum: float | None = None, open_end: bool = False) -> tuple[float, float]:
    """``w`` = (lo, hi) as two numbers with lo < hi (lo ≥ ``minimum``; hi may be +inf if ``open_end``)."""
    if isinstance(w, (str, bytes, dict)) or not hasattr(w, "__len__") or len(w) != 2:
        raise ConfigError(f"{name} must be a pair (lo, hi), got {w!r}")
    lo = number(w[0], f"{name}[0]", minimum=minimum)
    hi = w[1]
    if not (open_end and isinstance(hi, (int, float, np.integer, np.floating)) and hi == math.inf):
        hi = number(hi, f"{name}[1]")
    if not lo < hi:
        raise ConfigError(f"{name} must satisfy lo < hi, got {w!r}")
    return lo, float(hi)


def real(v, name: str) -> float:
    """``v`` as a float where NaN or inf may stand (a value not measured, a bound not set); never a word or None."""
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise ConfigError(f"{name} must be a number, got {v!r}")
    return float(v)


def having(obj, name: str, attributes: tuple[str, ...], kind: str):
    """``obj`` if it has every one of ``attributes`` (a result of ``kind``); the first one lacking is named."""
    lacking = [a for a in attributes if not hasattr(obj, a)]
    if lacking:
        raise ConfigError(f"{name} must be {kind}, got {type(obj).__name__} without {lacking[0]}")
    return obj
