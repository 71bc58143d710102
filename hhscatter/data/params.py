"""The physical parameters of a frame read from a run, and the check of a value typed again against them.

The readers of :mod:`hhscatter.data.read` leave what a frame was read from in ``DataFrame.attrs["hhscatter"]``
(:func:`hhscatter.data.read.run_identity`: the run's scene or grid as written in its ``scene.json``). An analysis
function that needs E0, γ, t_max or the section window of the run takes them from there; a value passed
explicitly is accepted only if it agrees with the data (:func:`checked_value`), otherwise ``ValueError`` names
the parameter, both values and where the data's value comes from. A frame that carries no such record (made
by pandas, DuckDB, … or by hand) is checked against what its rows say where they say it: the snapshots'
energies at t = 0 are the orbits' E0 (:func:`snapshot_energy_at_start`).

Example
-------
>>> import pandas as pd
>>> df = pd.DataFrame({"t": [0.0, 0.0], "energy": [0.3, 0.3]})
>>> df.attrs["hhscatter"] = {"run": "runs/a", "scene": {"energy": 0.3, "gamma": 0.01}}
>>> checked_value(df, "gamma", None, what="γ")
0.01
>>> checked_value(df, "gamma", 0.02, what="γ")
Traceback (most recent call last):
...
ValueError: gamma=0.02 contradicts the data: γ of runs/a is 0.01 (its scene.json); leave gamma out (it is read from the data)
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "FRAME_META",
    "checked_value",
    "frame_scene",
    "plain_point",
    "same_run",
    "same_value",
    "snapshot_energy_at_start",
]

FRAME_META = "hhscatter"  # the key of DataFrame.attrs the readers fill (hhscatter.data.read.FRAME_META)
RTOL = 1e-9  # a value typed again agrees with the data's to this relative tolerance (E0 of the orbits: last bits)


def frame_scene(frame) -> tuple[dict | None, str]:
    """frame_scene(frame) -> (scene dict, run) of a frame a reader made from one plain run, else (None, '').

    A grid run's scene is not one point's (its ``energy``/``gamma`` are lists: the frame's point columns say
    them) and a frame of several runs has no one scene: both give their scene only for the keys all points
    share (``t_max``, ``sections`` …), as the dict with the lists left in.
    """
    meta = getattr(frame, "attrs", {}).get(FRAME_META) or {}
    if "scene" in meta:
        return meta["scene"], meta.get("run", "")
    runs = meta.get("runs") or []
    if runs:
        scenes = [r.get("scene") or {} for r in runs]
        shared = {k: v for k, v in scenes[0].items() if all(s.get(k) == v for s in scenes[1:])}
        return shared, ", ".join(r.get("run", "") for r in runs)
    return None, ""


def same_value(a, b) -> bool:
    """same_value(a, b) -> True if two parameter values agree (floats to RTOL relative; dicts on the keys both
    have: a scene.json leaves out options at their defaults)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return all(same_value(a[k], b[k]) for k in a.keys() & b.keys())
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b))
    try:
        fa, fb = float(a), float(b)
    except (TypeError, ValueError):
        return a == b
    if math.isinf(fa) or math.isinf(fb) or math.isnan(fa) or math.isnan(fb):
        return fa == fb or (math.isnan(fa) and math.isnan(fb))
    return abs(fa - fb) <= RTOL * max(1.0, abs(fa), abs(fb)) if (fa and fb) else fa == fb


def checked_value(frame, key: str, value, *, what: str, name: str | None = None):
    """checked_value(frame, key, value, *, what, name=None) -> the data's value of scene key ``key``, or ``value``.

    The frame's scene (:func:`frame_scene`) gives ``key``: an explicit ``value`` that disagrees with it
    (:func:`same_value`) raises ValueError naming ``name`` (the argument, default ``key``), ``what`` (the
    quantity, e.g. "E0"), both values and the run. Without a record (or without ``key`` in it, or a grid's
    list) ``value`` is returned as given (None if not given).
    """
    scene, run = frame_scene(frame)
    have = None if scene is None else scene.get(key)
    if have is None or isinstance(have, list):
        return value
    if value is not None and not same_value(value, have):
        raise ValueError(
            f"{name or key}={value!r} contradicts the data: {what} of {run} is {have!r} (its scene.json); "
            f"leave {name or key} out (it is read from the data)"
        )
    return have


def snapshot_energy_at_start(snapshots) -> float | None:
    """snapshot_energy_at_start(snapshots) -> E0 of the orbits if the snapshots hold t = 0 and every orbit's
    energy there is one value (to RTOL: an ensemble on one energy shell), else None."""
    if not {"t", "energy"} <= set(snapshots.columns):
        return None
    e = snapshots["energy"].to_numpy(dtype=float)[snapshots["t"].to_numpy(dtype=float) == 0.0]
    if e.size == 0:
        return None
    med = float(np.median(e))
    return med if np.all(np.abs(e - med) <= RTOL * max(1.0, abs(med))) else None


def plain_point(frame, energy=None, gamma=None, *, what: str = "table") -> tuple:
    """plain_point(frame, energy=None, gamma=None) -> (energy, gamma) of the sections/snapshots of one run.

    A grid run's rows carry their point (``point_energy``/``point_gamma``): an explicit ``energy`` or ``gamma``
    must then be every row's, else ValueError; (energy, gamma) are returned as given. A plain run's E0 and γ
    come from the frame's record (:func:`checked_value`: an explicit value must agree); without a record, E0
    is the snapshots' energy at t = 0 when they hold it (:func:`snapshot_energy_at_start`), and an explicit
    ``energy`` that contradicts it is refused; γ is then taken as given (nothing in the rows says it). A plain
    frame whose E0 or γ is known neither way raises ValueError.
    """
    cols = set(frame.columns)
    if {"point_energy", "point_gamma"} <= cols:
        for arg, col, val in (("energy", "point_energy", energy), ("gamma", "point_gamma", gamma)):
            if val is None:
                continue
            have = sorted(set(frame[col].to_numpy(dtype=float).tolist()))
            if not all(same_value(val, h) for h in have):
                raise ValueError(
                    f"{arg}={val!r} contradicts the data: the {what}'s rows are of the grid point(s) "
                    f"{col} = {', '.join(f'{h:g}' for h in have)}; leave {arg} out (the rows say it)"
                )
        return energy, gamma
    scene, _ = frame_scene(frame)
    e = checked_value(frame, "energy", energy, what="E0", name="energy")
    g = checked_value(frame, "gamma", gamma, what="γ")
    if scene is None or scene.get("energy") is None:
        start = snapshot_energy_at_start(frame)
        if start is not None and e is not None and not same_value(e, start):
            raise ValueError(
                f"energy={e!r} contradicts the data: the {what}'s energy at t = 0 is {start:.12g} "
                "(every orbit's E0); leave energy out (it is read from the data)"
            )
        e = start if e is None else e
    if e is None or g is None:
        raise ValueError(
            f"the {what} has no point_energy/point_gamma columns and no record of its run: pass "
            f"energy= and gamma= (missing: {', '.join(k for k, v in (('energy', e), ('gamma', g)) if v is None)})"
        )
    return e, g


def same_run(a, b, *, what: str) -> None:
    """same_run(a, b, *, what) -> None; ValueError if frames ``a`` and ``b`` carry records of different runs
    (e.g. the lifetimes of one run with the sections of another)."""
    ma, mb = (getattr(x, "attrs", {}).get(FRAME_META) or {} for x in (a, b))
    ha, hb = ma.get("scene_hash"), mb.get("scene_hash")
    if ha and hb and ha != hb:
        raise ValueError(
            f"{what} come from different runs: {ma.get('run')} (scene {ha[:12]}…) and {mb.get('run')} "
            f"(scene {hb[:12]}…); pass the tables of one run"
        )
