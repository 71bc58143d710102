"""heyoka's integrators built from the declared events (:mod:`hhscatter.integrate.events`): the
batch and scalar integrators with the scene's events, their runtime parameters and the key of a compiled batch
integrator. The only place that constructs a heyoka event."""

from __future__ import annotations

import numpy as np

from hhscatter.integrate.events import HAMILTON_ONLY, Layout, Symbols, system


def build_batch(scene, batch_size: int, make_callback, *, tol=None, without=(), products=False):
    """build_batch(scene, batch_size, make_callback, without=(), products=False) -> (taylor_adaptive_batch, specs,
    layout).

    ``make_callback(spec)`` returns the callback object of one event (heyoka
    deep-copies it; bind handlers afterwards through ``ta.t_events[i].callback``).
    ``without``: names of events left out (an orbit phase that does not need them); ``products``: the events'
    H with its powers as products (:class:`hhscatter.integrate.events.Symbols`).
    """
    import heyoka as hy  # deferred: heyoka loads on first use

    lay = scene.layout
    specs = tuple(s for s in scene.events if s.name not in without)
    sym = Symbols(scene, lay, products)
    dirs = {+1: hy.event_direction.positive, -1: hy.event_direction.negative, 0: hy.event_direction.any}
    events = [
        hy.t_event_batch(s.expression(sym), callback=make_callback(s), direction=dirs[s.direction]) for s in specs
    ]
    pars = batch_pars(scene, lay, batch_size, without)
    kw = {"pars": pars} if len(pars) else {}
    ta = hy.taylor_adaptive_batch(
        system(scene, lay),
        np.zeros((lay.n_state, batch_size)),
        tol=scene.tol if tol is None else tol,
        t_events=events,
        **kw,
    )
    return ta, specs, lay


def build_escape_only_batch(scene, batch_size: int, callback, *, tol=None):
    """build_escape_only_batch(scene, batch_size, callback, tol=None) -> taylor_adaptive_batch: Hamilton's
    equations alone (x, y, px, py: no clock, no parameters) with the scene's conservative escape event, its
    callback ``callback``: the minimal driver of ``make bench-engine`` (benchmarks/engine.py, yardstick),
    which censors with its own propagation bound. The event is the engine's declaration, so both integrate
    the same escape; ``scene`` must be conservative and without a follow."""
    import heyoka as hy  # deferred: heyoka loads on first use

    (esc,) = (e for e in scene.events if e.name == "escape")
    ev = hy.t_event_batch(
        esc.expression(Symbols(scene, HAMILTON_ONLY)), callback=callback, direction=hy.event_direction.positive
    )
    return hy.taylor_adaptive_batch(
        system(scene, HAMILTON_ONLY), np.zeros((4, batch_size)), tol=scene.tol if tol is None else tol, t_events=[ev]
    )


def batch_pars(scene, lay: Layout, batch_size: int, without=()) -> np.ndarray:
    """batch_pars(scene, layout, batch_size, without=()) -> (n_pars, batch_size): the runtime parameters a
    batch integrator starts with (γ in every lane, the section gate closed)."""
    # the gate is the last parameter: without the section event heyoka's system has none
    n_pars = lay.n_pars - (1 if lay.gate is not None and "section" in without else 0)
    pars = np.zeros((n_pars, batch_size))
    if lay.gamma is not None:
        pars[lay.gamma] = scene.gamma
    return pars


def batch_key(scene, batch_size: int, *, tol=None, without=(), products=False) -> tuple:
    """batch_key(scene, batch_size, tol=None, without=(), products=False) -> (key, specs, layout).

    ``key`` (hashable) holds everything :func:`build_batch` compiles: the system and the event
    expressions as heyoka prints them (constants to 17 digits, which round-trip), the events'
    directions and rules, the tolerance, the layout and the batch size. Two calls with equal keys
    give interchangeable integrators: what differs between them (γ, the section gate) is a runtime
    parameter, set per chunk (:func:`batch_pars`). Costs ~0.1 ms, no compilation.
    """
    return scene.cached(
        ("batch key", batch_size, tol, without, products), lambda: _key(scene, batch_size, tol, without, products)
    )


def _key(scene, batch_size, tol, without, products):
    lay = scene.layout
    specs = tuple(s for s in scene.events if s.name not in without)
    sym = Symbols(scene, lay, products)
    key = (
        batch_size,
        float(scene.tol if tol is None else tol),
        lay,
        repr(system(scene, lay)),
        tuple((s.name, s.rule, s.index, s.direction, repr(s.expression(sym))) for s in specs),
    )
    return key, specs, lay


def build_scalar(scene, make_callback, *, fp_type=float, tol=None, section_cooldown=-1.0, products=False):
    """build_scalar(scene, make_callback, fp_type=float, tol=None, section_cooldown=-1, products=False) ->
    (taylor_adaptive, specs, layout).

    The same events on heyoka's scalar integrator, in ``fp_type`` (float,
    numpy.longdouble or heyoka.real128). ``tol`` defaults to the scene's for
    float and to the type's epsilon otherwise. ``section_cooldown``: the section event's cooldown after a root
    (time units; −1: heyoka's, deduced from the event's derivative at the root, as for every other event).
    ``products``: the events' H with its powers as products (:class:`hhscatter.integrate.events.Symbols`).
    """
    import heyoka as hy  # deferred: heyoka loads on first use

    lay = scene.layout
    specs = scene.events
    sym = Symbols(scene, lay, products)
    dirs = {+1: hy.event_direction.positive, -1: hy.event_direction.negative, 0: hy.event_direction.any}
    cast = caster(fp_type)
    events = [
        hy.t_event(
            s.expression(sym),
            callback=make_callback(s),
            direction=dirs[s.direction],
            cooldown=fp_type(section_cooldown if s.rule == "section" else -1.0),
            fp_type=fp_type,
        )
        for s in specs
    ]
    pars = [0.0] * lay.n_pars
    if lay.gamma is not None:
        pars[lay.gamma] = scene.gamma
    kw = {}
    if tol is not None or fp_type is float:
        t = scene.tol if tol is None else tol
        kw["tol"] = fp_type(t) if fp_type is not float else t
    ta = hy.taylor_adaptive(
        system(scene, lay),
        cast([0.0] * lay.n_state),
        pars=cast(pars) if pars else [],
        t_events=events,
        fp_type=fp_type,
        **kw,
    )
    return ta, specs, lay


def caster(fp_type):
    """caster(fp_type) -> function turning a list/array of floats into what heyoka's constructor takes."""
    if fp_type is float:
        return lambda v: np.asarray(v, dtype=float)
    if fp_type is np.longdouble:
        return lambda v: np.asarray(v, dtype=np.longdouble)
    return lambda v: [fp_type(float(a)) for a in np.asarray(v, dtype=float)]


__all__ = [
    "batch_key",
    "batch_pars",
    "build_batch",
    "build_escape_only_batch",
    "build_scalar",
    "caster",
]
