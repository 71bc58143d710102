"""The chunk: ``run_chunk(scene, ics, traj_ids) -> ChunkResult``, one block of orbits on one batch integrator."""

from __future__ import annotations

import warnings

import numpy as np

from hhscatter.integrate import events, heyoka_log
from hhscatter.integrate.events import ESCAPED
from hhscatter.integrate.lanes import RERUN
from hhscatter.integrate.plan import plan_of
from hhscatter.integrate.rerun import _merge_rerun, _no_return, _orbits_with_failures, _own_far, _redo_on_reference
from hhscatter.integrate.results import CROSSING_COLUMNS, SECTION_COLUMNS, ChunkResult, _empty_result, _rows_to_columns


def scheduler(scene) -> str:
    """scheduler(scene) -> the name of the scheduler that integrates the scene (a registered one,
    :mod:`hhscatter.integrate.schedulers`): 'noise' for scenes with noise, 'epochs' for scenes with snapshots,
    else 'stream'."""
    return plan_of(scene).scheduler


def run_chunk(scene, ics, traj_ids, *, batch_size=None, count_steps=False, progress=None) -> ChunkResult:
    """run_chunk(scene, ics, traj_ids, batch_size=None, count_steps=False, progress=None) -> ChunkResult.

    ``scene``: the scene's :class:`hhscatter.integrate.plan.Plan` (a run builds it once), or a scene (its plan
    is built here). ``ics``: array (n, 4) of initial states (x, y, px, py); ``traj_ids``: int64
    array (n,). Returns the table rows of this chunk, ordered by traj_id (and
    time). ``batch_size`` (default: the scene's, else 8 lanes for the stream
    scheduler and 16 for epochs) has no effect on the results. ``count_steps``:
    fill ``ChunkResult.n_steps`` (the epoch scheduler otherwise skips reading
    heyoka's per-lane results every epoch; the stream scheduler always counts).
    ``progress``: a callable f(k), called with k = PROGRESS_EVERY each time
    that many more orbits of the chunk have started, so long chunks show
    progress.

    With the tangent dynamics, the orbits whose log-stretch Λ at t_end exceeds
    :data:`hhscatter.integrate.events.MAX_LOG_STRETCH` are counted (``ChunkResult.tangent_beyond``) and warned of
    (:class:`hhscatter.integrate.events.TangentStretchWarning`): a finite Λ is kept, a non-finite one (the vector
    overflowed) is written as NaN; a tangent vector that makes heyoka's state non-finite stops the chunk with a
    FloatingPointError that says so.

    heyoka's log is captured while the chunk runs (:mod:`hhscatter.integrate.heyoka_log`): an event whose root
    finding failed in a step is ignored there by heyoka, so every such failure is counted
    (``ChunkResult.event_failures``), the orbits it hit are found (:func:`_orbits_with_failures`) and redone
    on the long-double reference driver (:func:`_redo_on_reference`; ``ChunkResult.redone`` their traj_ids).
    An orbit that starts on the section near an inflection of r has its section window opened at T_INITIAL
    by the clock (:func:`hhscatter.integrate.events.opens_late`), or, in a scene without a clock, is redone
    on the reference driver too. A noise scene's orbits have no reference driver (their kicks live in the
    noise scheduler, not :attr:`hhscatter.integrate.schedulers.Scheduler.deterministic`): their failures are
    counted, not redone.
    """
    scene = plan_of(scene)
    ics = np.ascontiguousarray(ics, dtype=float)
    traj_ids = np.asarray(traj_ids, dtype=np.int64)
    outside = ics[:, 0] ** 2 + ics[:, 1] ** 2 >= scene.r_esc**2
    inside = ~outside
    deterministic = scene.kind.deterministic
    # the integration's plan (maybe an earlier far event) and `late`
    far = _no_return(scene, ics[inside]) if deterministic else (scene, None)
    kw = dict(batch_size=batch_size, count_steps=count_steps)
    with heyoka_log.capture() as log:
        res = _integrate(scene, ics[inside], traj_ids[inside], far, progress=progress, **kw)
    failures, redone = log.event_failures, np.empty(0, np.int64)
    local = _unclocked_late(scene, ics[inside]) if deterministic else np.empty(0, np.int64)
    if failures and deterministic:
        found = _orbits_with_failures(
            lambda idx: _integrate(scene, ics[inside][idx], traj_ids[inside][idx], far, **kw),
            int(inside.sum()),
            failures,
        )
        local = np.union1d(local, found)
    if len(local):
        res = _redo_on_reference(scene, res, ics[inside], traj_ids[inside], local)
        redone = traj_ids[inside][local]
    if outside.any():  # region 'square' (or an IC table): escaped at t = 0, not integrated
        res = _with_escaped_at_start(scene, ics, traj_ids, outside, res)
    res.event_failures, res.redone = failures, redone
    if "log_stretch" in res.lifetimes:  # the tangent dynamics: orbits whose Λ passed MAX_LOG_STRETCH, counted
        lam = res.lifetimes["log_stretch"]
        bad = ~np.isfinite(lam)
        lam[bad] = np.nan  # a tangent vector that overflowed: no log-stretch
        res.tangent_beyond = events.stretch_beyond(lam)
        if res.tangent_beyond:
            warnings.warn(
                f"{res.tangent_beyond} of {len(ics)} orbit(s) reached a log-stretch Λ above "
                f"{events.MAX_LOG_STRETCH:g} ({int(bad.sum())} of them not finite, written as NaN): their tangent "
                "vector may have set steps, their orbits are not guaranteed to be those of the scene without the "
                "tangent dynamics (a shorter t_max keeps Λ below it)",
                events.TangentStretchWarning,
                stacklevel=2,
            )
    return res


def _opens_late(scene, ics):
    """events.opens_late where the scene has the clock that opens those windows at T_INITIAL, else None."""
    return events.opens_late(scene, ics) if scene.layout.clock is not None else None


def _unclocked_late(scene, ics) -> np.ndarray:
    """Local indices of the orbits whose window should open late (events.opens_late) in a scene without a clock
    (snapshots, a window open from 0 to the end): they are redone on the reference driver (its section cooldown
    is fixed: events.SECTION_COOLDOWN)."""
    if scene.layout.clock is not None:
        return np.empty(0, np.int64)
    late = events.opens_late(scene, ics)
    return np.flatnonzero(late) if late is not None else np.empty(0, np.int64)


def _integrate(
    scene, ics, traj_ids, far, *, batch_size=None, count_steps=False, progress=None, products=None
) -> ChunkResult:
    """The chunk's orbits (all inside r_esc) on the batch engine; ``far``: :func:`_no_return`'s (scene, late),
    fixed by the caller so that any subset of the chunk is integrated exactly as in the chunk.

    ``products``: the events' H with its powers written as products (True) or as the system gives it (False);
    None: the system's, and the orbits that start where a power of H has a zero base
    (:func:`hhscatter.integrate.events.zero_power_start`: heyoka would skip their closure event in the first step)
    are integrated again in products, their rows replacing the first ones."""
    if not len(ics):
        return _empty_result(traj_ids)
    kw = dict(batch_size=batch_size, count_steps=count_steps)
    if products is None:
        res = _integrate(scene, ics, traj_ids, far, progress=progress, products=False, **kw)
        zero = events.zero_power_start(scene, ics)
        if zero is not None:
            res = _merge_rerun(
                res, zero, traj_ids, _integrate(scene, ics[zero], traj_ids[zero], far, products=True, **kw)
            )
        return res
    kind = scene.kind
    B = int(batch_size or scene.batch_size or kind.batch_size)
    orig, (scene, late) = scene, far
    config = dict(count_steps=count_steps, progress=progress, late=late, open_late=_opens_late(scene, ics))
    lanes, n_returns, n_steps, (s_ids, s_t, s_e) = kind.integrate(scene, B, ics, traj_ids, products=products, **config)
    outcome = lanes.outcome
    if (outcome == -1).any():
        raise RuntimeError("internal error: some orbits of the chunk have no outcome")
    res = _chunk_result(scene, lanes, ics, traj_ids, outcome, (s_ids, s_t, s_e), n_returns, n_steps)
    rerun = outcome == RERUN
    if rerun.any():  # decided at the no-return radius too close to t_max: the scene's own rule decides
        own = _own_far(orig)
        res = _merge_rerun(
            res,
            rerun,
            traj_ids,
            _integrate(own, ics[rerun], traj_ids[rerun], (own, None), products=products, **kw),
        )
    return res


def _chunk_result(scene, lanes, ics, traj_ids, outcome, snaps, n_returns, n_steps) -> ChunkResult:
    """The chunk's rows from its lanes: lifetimes in orbit order, the other tables by orbit, then time."""
    n, (s_ids, s_t, s_e) = len(ics), snaps
    model = scene.model
    end = lanes.end_state
    t_end = lanes.orbit_times()
    channel = np.where(outcome == ESCAPED, model.exit_channel(end[:, 0], end[:, 1]), -1)
    lifetimes = {
        "traj_id": traj_ids,
        "x0": ics[:, 0].copy(),
        "y0": ics[:, 1].copy(),
        "px0": ics[:, 2].copy(),
        "py0": ics[:, 3].copy(),
        "e0": model.energy(ics[:, 0], ics[:, 1], ics[:, 2], ics[:, 3]),
        "gamma": np.full(n, scene.gamma),
        "outcome": outcome,
        "t_end": t_end,
        "exit_channel": channel.astype(np.int8),
        "e_end": model.energy(end[:, 0], end[:, 1], end[:, 2], end[:, 3]),
    }
    if scene.layout.tangent is not None:  # Λ at t_end
        lifetimes["log_stretch"] = lanes.end_stretch.copy()
    sections = _rows_to_columns(lanes.sec_rows, SECTION_COLUMNS, traj_ids)
    crossings = _rows_to_columns(lanes.cross_rows, CROSSING_COLUMNS, traj_ids)
    crossings["direction"] = crossings["direction"].astype(np.int8)
    order = np.lexsort((s_t, s_ids))
    snapshots = {"traj_id": traj_ids[s_ids[order]], "t": s_t[order], "energy": s_e[order]}
    return ChunkResult(lifetimes, sections, snapshots, crossings, n_returns=n_returns, n_steps=int(n_steps))


def _with_escaped_at_start(scene, ics, traj_ids, outside, res):
    """The chunk's result from ``res`` (its orbits that start inside r_esc) and the orbits ``outside`` (a mask):
    those start at r ≥ r_esc and are escaped at t = 0 (the authors' square ICs). Rows keep traj_id order."""
    inside = ~outside
    model = scene.model
    x, y, px, py = ics.T
    lt = {
        "traj_id": traj_ids,
        "x0": x.copy(),
        "y0": y.copy(),
        "px0": px.copy(),
        "py0": py.copy(),
        "e0": model.energy(x, y, px, py),
        "gamma": np.full(len(ics), scene.gamma),
        "outcome": np.full(len(ics), ESCAPED, np.int8),
        "t_end": np.zeros(len(ics)),
        "exit_channel": model.exit_channel(x, y).astype(np.int8),
        "e_end": model.energy(x, y, px, py),
    }
    if scene.layout.tangent is not None:
        lt["log_stretch"] = np.zeros(len(ics))
    if inside.any():
        for col in [c for c in ("outcome", "t_end", "exit_channel", "e_end", "log_stretch") if c in lt]:
            lt[col][inside] = res.lifetimes[col]
    snaps = res.snapshots
    if scene.snapshots and scene.snapshots[0] == 0.0:  # a snapshot at t = 0 ≤ t_end of the escaped ones
        ids = np.concatenate([snaps["traj_id"], traj_ids[outside]])
        t = np.concatenate([snaps["t"], np.zeros(int(outside.sum()))])
        e = np.concatenate([snaps["energy"], lt["e0"][outside]])
        order = np.lexsort((t, ids))
        snaps = {"traj_id": ids[order], "t": t[order], "energy": e[order]}
    return ChunkResult(lt, res.sections, snaps, res.crossings, n_returns=res.n_returns, n_steps=res.n_steps)
