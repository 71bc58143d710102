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
    significant digits) and ``gamma``. Raises ValueError if the frame is empty
    or lacks ``t_end``/``outcome``.
    """
    cols = set(lifetimes.columns)
    missing = {"t_end", "outcome"} - cols
    if missing:
        raise ValueError(f"lifetimes lacks column(s) {sorted(missing)}: pass a frame of hhscatter.read_lifetimes")
    if len(lifetimes) == 0:
        raise ValueError("lifetimes is empty: no orbits to analyse")
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
    for e, g in pairs:
        mask = (key_e == e) & (gamma == g)
        out.append(((math.nan if e == -np.inf else float(e), float(g)), lifetimes[mask]))
    return out


def _label(key) -> str:
    e, g = key
    return f"E0={e:g}, γ={g:g}" if math.isfinite(e) else f"γ={g:g}"


def _sorted_keys(keys):
    return sorted(keys, key=lambda k: (np.nan_to_num(k[0], nan=-np.inf), k[1]))


def _same_point(a, b) -> bool:
    """Two (energy, gamma) keys name the same point (energies to 1e-9 relative, NaN equal to NaN)."""
    (ea, ga), (eb, gb) = a, b
    same_e = (math.isnan(ea) and math.isnan(eb)) or (math.isfinite(ea) and math.isfinite(eb)
                                                     and abs(ea - eb) <= E0_RTOL * max(1.0, abs(ea)))
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
    raise ValueError(f"the {what} has no point_energy/point_gamma columns (a plain run): pass energy= and gamma=, "
                     "or the lifetimes of that one run")


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
