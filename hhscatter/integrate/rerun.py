"""Orbits of a chunk integrated again: the no-return rule's late orbits (rerun to the scene's own far radius)
and the orbits hit by a heyoka event-detection failure (found and redone on the reference driver)."""

from __future__ import annotations

import math

import numpy as np

from hhscatter.integrate import heyoka_log
from hhscatter.integrate.events import ESCAPED
from hhscatter.integrate.reference import simulate_orbit
from hhscatter.integrate.results import CROSSING_COLUMNS, SECTION_COLUMNS, ChunkResult

NO_RETURN_GRID = 1.0 / 8.0  # the no-return far radius is rounded up to this fraction of r_s (fewer compiles)
FAR_BEYOND_RESC = 0.01  # ... and lies at least this fraction beyond r_esc (its root is never r_esc's)


def _orbits_with_failures(integrate, n, failures) -> np.ndarray:
    """_orbits_with_failures(integrate, n, failures) -> sorted local indices of the orbits whose integration logs
    event-detection failures, among 0..n−1 that logged ``failures`` together.

    ``integrate(idx)`` integrates the orbits ``idx`` of the chunk as the chunk did (an orbit's steps do not depend
    on the orbits beside it: the engine's determinism), so a failure comes back with its orbit: halves are
    integrated under capture, and the halves with failures split again (about 2n orbit integrations per failing
    orbit). A set whose failures no half reproduces is returned whole (every orbit of it is redone).
    """

    def count(idx):
        with heyoka_log.capture() as log:
            integrate(idx)
        return log.event_failures

    found = []

    def split(idx, k):
        if len(idx) == 1:
            found.append(idx)
            return
        halves = (idx[: len(idx) // 2], idx[len(idx) // 2 :])
        counts = [count(h) for h in halves]
        if not any(counts):  # not reproduced orbit by orbit: keep the whole set
            found.append(idx)
            return
        for h, c in zip(halves, counts):
            if c:
                split(h, c)

    split(np.arange(n), failures)
    return np.unique(np.concatenate(found))


def _redo_on_reference(scene, res, ics, traj_ids, local) -> ChunkResult:
    """res with the orbits ``local`` (indices into the chunk) redone one by one on the reference driver
    (:func:`simulate_orbit`) in long double, then real128, until one run logs no event-detection failure; its
    times and states rounded to double. Raises RuntimeError if none succeeds.

    (An orbit that starts on the section is on it exactly in double, x p_x + y p_y = 0; in long double the same
    numbers carry a radial velocity of ~1e-17, which at an inflection of r puts a crossing ~1e-8 after the
    start: within :data:`hhscatter.integrate.events.T_INITIAL`, the initial point, as in double.)"""
    import heyoka as hy  # deferred: heyoka loads on first use

    model = scene.model
    rows = {"lifetimes": [], "sections": [], "snapshots": [], "crossings": []}
    for j in local:
        for fp in (np.longdouble, getattr(hy, "real128", None)):
            if fp is None:
                continue
            with heyoka_log.capture() as log:
                o = simulate_orbit(scene, ics[j], fp_type=fp)
            if not log.event_failures:
                break
        else:
            raise RuntimeError(
                f"orbit {traj_ids[j]}: heyoka's event detection failed in double, long double and real128"
            )
        k = traj_ids[j]
        end = np.array([float(v) for v in o.state_end[:4]])
        rows["lifetimes"].append((j, o.outcome, float(o.t_end), end, o.log_stretch))
        rows["sections"] += [(k, *(float(v) for v in r)) for r in o.sections]
        rows["snapshots"] += [(k, float(t), *(float(v) for v in st[:4])) for t, st in o.snapshots]
        rows["crossings"] += [(k, float(t), float(R), int(d)) for t, R, d in o.crossings]
    sel = np.array([r[0] for r in rows["lifetimes"]], dtype=np.int64)
    end = np.array([r[3] for r in rows["lifetimes"]]).reshape(-1, 4)
    outcome = np.array([r[1] for r in rows["lifetimes"]], dtype=np.int8)
    x, y, px, py = ics[sel].T
    lifetimes = {
        "traj_id": traj_ids[sel],
        "x0": x.copy(),
        "y0": y.copy(),
        "px0": px.copy(),
        "py0": py.copy(),
        "e0": model.energy(x, y, px, py),
        "gamma": np.full(len(sel), scene.gamma),
        "outcome": outcome,
        "t_end": np.array([r[2] for r in rows["lifetimes"]], dtype=float),
        "exit_channel": np.where(outcome == ESCAPED, model.exit_channel(end[:, 0], end[:, 1]), -1).astype(np.int8),
        "e_end": model.energy(end[:, 0], end[:, 1], end[:, 2], end[:, 3]),
    }
    if scene.layout.tangent is not None:
        lifetimes["log_stretch"] = np.array([r[4] for r in rows["lifetimes"]], dtype=float)
    snap = np.array(rows["snapshots"], dtype=float).reshape(-1, 6)
    snapshots = {
        "traj_id": snap[:, 0].astype(np.int64),
        "t": snap[:, 1],
        "energy": model.energy(snap[:, 2], snap[:, 3], snap[:, 4], snap[:, 5]),
    }
    sec = np.array(rows["sections"], dtype=float).reshape(-1, len(SECTION_COLUMNS))
    sections = {c: sec[:, i] for i, c in enumerate(SECTION_COLUMNS)}
    cr = np.array(rows["crossings"], dtype=float).reshape(-1, len(CROSSING_COLUMNS))
    crossings = {c: cr[:, i] for i, c in enumerate(CROSSING_COLUMNS)}
    for t in (sections, crossings):
        t["traj_id"] = t["traj_id"].astype(np.int64)
    crossings["direction"] = crossings["direction"].astype(np.int8)
    mask = np.zeros(len(ics), dtype=bool)
    mask[sel] = True
    again = ChunkResult(lifetimes, sections, snapshots, crossings)
    return _merge_rerun(res, mask, traj_ids, again)


def _own_far(scene):
    """The scene with its own far radius written out: integrated under the scene's rule, not the no-return one."""
    return scene.replace(r_far=scene.far_radius)


def _no_return(scene, ics):
    """_no_return(plan, ics) -> (plan to integrate, late): the no-return rule of dissipative scenes.

    An escaped dissipative orbit is decided at its last outward r_esc crossing (t_end, its state); the scene
    follows it on to r_far = max(10 r_s, 2 r_esc) only to know that no crossing comes after. The system's
    no-return radius R(E) (:meth:`hhscatter.model.base.System.no_return_radius`) proves that earlier: an
    orbit of energy ≤ E at r ≥ R with ṙ > 0 never returns, under either drag law. With E the largest
    initial energy of the chunk (the energy only falls), the far event moves to max(R(E), (1 + 1 %) r_esc),
    rounded up to r_s/8 (so that chunks share one compiled integrator); the outcome, t_end and end state are
    the same at either radius, and no recorded row lies after t_end.

    The one thing r_far still decides: an orbit that has not reached r_far by t_max is censored there.
    ``late(t, x, y, px, py)`` tells at the no-return radius whether that can happen; such an orbit is rerun with the
    scene's own far event (exactly as before: tables byte-identical for the same scene hash). A censored orbit
    never reached R, so its steps are the same under either far event (the clock censors it in orbit time, a
    stream lane's history does not enter). The bound: beyond
    R the radial force is outward, so with the linear drag ṗ_r ≥ −γ p_r, p_r(t) ≥ p_r e^{−γτ}, and r_far is
    reached within τ = −ln(1 − γ(r_far − r)/p_r)/γ (taken with 1 % and 1e-6 of slack); an orbit for which
    that is infinite or ends after t_max is late. Applies to linear drag with the default r_far (a scene with
    an explicit ``r_far`` keeps it, so does quadratic drag, for which no such bound is written down).
    """
    m = scene.model
    if scene.gamma <= 0 or scene.r_far is not None or m.dissipation != "linear" or not len(ics):
        return scene, None
    r_far = scene.far_radius
    e0 = float(np.max(m.energy(ics[:, 0], ics[:, 1], ics[:, 2], ics[:, 3])))
    grid = NO_RETURN_GRID * m.saddle_radius
    R = max(m.no_return_radius(e0 + 1e-12 * abs(e0)) * (1.0 + 1e-9), float(scene.r_esc) * (1.0 + FAR_BEYOND_RESC))
    R = math.ceil(R / grid) * grid
    if R >= r_far:
        return scene, None
    gamma, t_max = float(scene.gamma), float(scene.t_max)

    def late(t, x, y, px, py):
        r = math.sqrt(x * x + y * y)
        pr = (x * px + y * py) / r
        a = gamma * (r_far - r)
        if not pr > 0.0 or a >= 0.999 * pr:
            return True
        return t + 1.01 * (-math.log1p(-a / pr) / gamma) + 1e-9 * t_max + 1e-6 >= t_max

    return scene.replace(r_far=R), late


def _merge_rerun(res, rerun, traj_ids, again):
    """res with the orbits ``rerun`` (mask over the chunk) replaced by their rerun ``again``: lifetimes
    entries overwritten, their rows of the other tables taken from ``again``, rows kept in (orbit, t) order."""
    for col, v in res.lifetimes.items():
        v[rerun] = again.lifetimes[col]
    srt = np.argsort(traj_ids, kind="stable")
    sorted_ids = traj_ids[srt]

    def local(ids):  # traj_id -> position in the chunk
        return srt[np.searchsorted(sorted_ids, ids)]

    tables = {}
    for name in ("sections", "snapshots", "crossings"):
        a, b = getattr(res, name), getattr(again, name)
        keep = ~rerun[local(a["traj_id"])]
        cols = {c: np.concatenate([a[c][keep], b[c].astype(a[c].dtype)]) for c in a}
        order = np.lexsort((cols["t"], local(cols["traj_id"])))
        tables[name] = {c: v[order] for c, v in cols.items()}
    return ChunkResult(
        res.lifetimes,
        tables["sections"],
        tables["snapshots"],
        tables["crossings"],
        n_returns=res.n_returns + again.n_returns,
        n_steps=res.n_steps + again.n_steps,
    )
