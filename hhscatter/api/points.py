"""Grid points: the ensembles of a lifetimes frame, one per (energy, γ), and the helpers every concept shares.

An *ensemble* (a grid point) is one (energy, γ): the nominal E0 in the
``energy`` column of a grid run, never the per-orbit ``e0``, which differs
from orbit to orbit in the last bits. A frame without ``energy`` (a plain run,
or several plain runs concatenated) is split by clustering ``e0`` with a
relative tolerance of 1e-9; a frame whose ``e0`` varies continuously (a run
from an initial-condition table) is one ensemble per γ, with energy NaN.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from hhscatter.api import checks
from hhscatter.errors import ConfigError
from hhscatter.outcomes import OUTCOMES

if TYPE_CHECKING:  # annotations only: pandas and matplotlib are imported when a function runs
    import pandas

E0_RTOL = 1e-9  # e0 of one ensemble differs in the last bits only
MAX_E0_CLUSTERS = 50  # beyond this, e0 varies continuously (an ics run): one ensemble per γ


def _clusters(values: np.ndarray) -> np.ndarray:
    """Label of each value's cluster: sorted values split where the gap exceeds E0_RTOL (relative)."""
    order = np.argsort(values, kind="stable")
    v = values[order]
    gap = np.diff(v) > E0_RTOL * np.maximum(1.0, np.abs(v[1:]))
    labels = np.empty(v.size, dtype=np.int64)
    labels[order] = np.concatenate([[0], np.cumsum(gap)])
    return labels


def split_points(lifetimes):
    """The ensembles of a lifetimes frame: [((energy, gamma), sub-DataFrame)], sorted by energy then γ.

    The ensembles of a lifetimes frame (module doc): by the ``energy`` and
    ``gamma`` columns when present; otherwise by clusters of ``e0`` (relative
    tolerance 1e-9; the key's energy is the cluster's median e0 to 12
    significant digits) and ``gamma``. A frame of several runs
    (:func:`hhscatter.read_lifetimes` of a list: a ``run`` column) is split per
    run too, with keys ``(energy, gamma, run)``: one point per run and grid
    point, unless the runs were pooled (``read_lifetimes(runs, pool=True)``).
    Raises ConfigError (a ValueError) if ``lifetimes`` is not a DataFrame, is
    empty, lacks ``t_end``/``outcome``, has a ``t_end``, ``energy``, ``e0`` or
    ``gamma`` that is not a number (NaN, negative times or γ), an ``outcome``
    that is not one of the table's, or holds an orbit (``traj_id``) twice in one
    point (the same run concatenated twice).
    """
    checks.frame(lifetimes, "lifetimes", needs=("t_end", "outcome"))
    _check_columns(lifetimes)
    cols = set(lifetimes.columns)
    pooled = (lifetimes.attrs.get("hhscatter") or {}).get("pooled") is not None
    if "run" in cols and not pooled:
        out = [
            ((*key, str(run)), df)
            for run, sub in lifetimes.groupby("run", observed=True, sort=False)
            for key, df in _split_one(sub)
        ]
        return sorted(out, key=lambda kv: _sort_key(kv[0]))
    return _split_one(lifetimes)


def _check_columns(lifetimes) -> None:
    """The values a split and the estimators rely on: t_end finite and ≥ 0, γ finite and ≥ 0, energies finite
    (NaN allowed: a point without a nominal E0), outcomes of the table's vocabulary."""
    import pandas as pd  # deferred: pandas loads on first use

    checks.numeric_columns(lifetimes, "lifetimes", nonneg=("t_end", "gamma"), finite=("e0",), nan_ok=("energy",))
    outcome = lifetimes["outcome"].astype(object)
    unknown = sorted({str(o) for o in pd.unique(outcome)} - set(OUTCOMES), key=str)
    if unknown:
        raise ConfigError(f"lifetimes column outcome holds {unknown[:3]}: an outcome is one of {', '.join(OUTCOMES)}")


def _split_one(lifetimes):
    """split_points of the rows of one run (or of runs pooled on purpose); an orbit twice in a point refused."""
    cols = set(lifetimes.columns)
    n = len(lifetimes)
    gamma = lifetimes["gamma"].to_numpy(dtype=float) if "gamma" in cols else np.zeros(n)
    if "energy" in cols:
        energy = lifetimes["energy"].to_numpy(dtype=float)
    elif "e0" in cols:
        e0 = lifetimes["e0"].to_numpy(dtype=float)
        labels = _clusters(e0)
        if labels.max() + 1 > MAX_E0_CLUSTERS:
            energy = np.full(n, math.nan)
        else:
            med = {k: float(f"{np.median(e0[labels == k]):.12g}") for k in np.unique(labels)}
            energy = np.array([med[k] for k in labels])
    else:
        energy = np.full(n, math.nan)
    key_e = np.where(np.isnan(energy), -np.inf, energy)  # NaN sorts and compares as one value
    pairs = np.unique(np.column_stack([key_e, gamma]), axis=0)
    out = []
    ids = ["run", "traj_id"] if "run" in cols else ["traj_id"]
    for e, g in pairs:
        mask = (key_e == e) & (gamma == g)
        key, df = (math.nan if e == -np.inf else float(e), float(g)), lifetimes[mask]
        if "traj_id" in cols and df.duplicated(subset=ids).any():
            raise ConfigError(
                f"lifetimes holds orbits twice at {_label(key)} (traj_id repeated): the same run "
                "concatenated twice, or several runs without a run column; read several runs with "
                "hhscatter.read_lifetimes([run1, run2, …]), which keeps them apart"
            )
        out.append((key, df))
    return out


def _sort_key(k):
    """Order of point keys: energy (NaN first), γ, then the run (as given)."""
    return (float(np.nan_to_num(k[0], nan=-np.inf)), k[1], *(str(x) for x in k[2:]))


def _key_columns(key) -> dict:
    """The columns a point key gives a result row: energy, gamma (and run, for a frame of several runs)."""
    return {"energy": key[0], "gamma": key[1], **({"run": key[2]} if len(key) > 2 else {})}


def _label(key) -> str:
    e, g = key[0], key[1]
    head = f"E0={e:g}, γ={g:g}" if math.isfinite(e) else f"γ={g:g}"
    return f"{head} ({key[2]})" if len(key) > 2 else head


def _sorted_keys(keys):
    return sorted(keys, key=_sort_key)


def _same_point(a, b) -> bool:
    """Two (energy, gamma[, run]) keys name the same point (energies to 1e-9 relative, NaN equal to NaN; the
    runs equal when both keys name one)."""
    if len(a) > 2 and len(b) > 2 and a[2] != b[2]:
        return False
    (ea, ga), (eb, gb) = a[:2], b[:2]
    same_e = (math.isnan(ea) and math.isnan(eb)) or (
        math.isfinite(ea) and math.isfinite(eb) and abs(ea - eb) <= E0_RTOL * max(1.0, abs(ea))
    )
    return same_e and ga == gb


def _split_like(table, keys, *, energy=None, gamma=None, what="table"):
    """{key: rows of ``table`` of that point}: by ``point_energy``/``point_gamma`` (a grid run's sections or
    snapshots); a table without them belongs to the one point of ``keys`` (or to ``energy``/``gamma``)."""
    cols = set(table.columns)
    if {"point_energy", "point_gamma"} <= cols:  # a grid run: the points' nominal E0 and γ, exact values
        out = {}
        for (e, g), df in table.groupby(["point_energy", "point_gamma"], sort=True, dropna=False):
            key = (float(e), float(g))
            match = [k for k in keys if _same_point(k, key)] if keys else [key]
            if match:
                out[match[0]] = df
        return out
    if energy is not None or gamma is not None:
        return {(math.nan if energy is None else float(energy), 0.0 if gamma is None else float(gamma)): table}
    if keys is not None and len(keys) == 1:
        return {keys[0]: table}
    raise ConfigError(
        f"the {what} has no point_energy/point_gamma columns (a plain run): pass energy= and gamma=, "
        "or the lifetimes of that one run"
    )


@dataclass(frozen=True)
class _PointRows:
    """A result made of one row of numbers per grid point: ``rows[(energy, gamma)]`` → dict."""

    rows: dict

    def __getitem__(self, key):
        return self.rows[key]

    def to_frame(self) -> pandas.DataFrame:
        """The rows as a DataFrame, one per point (sorted by energy, then γ)."""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.DataFrame([self.rows[k] for k in _sorted_keys(self.rows)])
