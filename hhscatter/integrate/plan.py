"""The engine's plan of a scene: what the engine needs from a scene, frozen once, and what it derives from it.

:func:`plan_of` reads a scene's values once (the system, times, radii, what it records, its noise) and derives
the rest once: the scheduler (:mod:`hhscatter.integrate.schedulers`), the clock's targets, the state and
parameter layout, the events, the far radius, whether the section event waits for a second phase. Every engine
function takes the plan; nothing in the engine reads a scene or recomputes what the plan holds, and the engine
imports neither :mod:`hhscatter.scene` nor :mod:`hhscatter.model`: the plan carries the system object, whose
expression builders the engine calls with the heyoka module (heyoka is imported only by the engine).

A run builds the plan of each of its scenes once, where it accepts the scene (:func:`hhscatter.run.runner.simulate`),
and pickles it with the scene (:func:`hhscatter.run.worker.pack_point`): every chunk, in this process, a pool's
worker process or on a Dask worker, gets those bytes and unpickles the plan as it is (its derived values included:
nothing is derived again; each process unpickles a point's plan once).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

# the built-in schedulers register themselves on import
from hhscatter.integrate import epochs, events, noise, noise_symplectic, stream  # noqa: F401
from hhscatter.integrate.events import Layout
from hhscatter.integrate.schedulers import SCHEDULERS, select

#: the scene values a plan copies (a scene's attributes of these names)
SCENE_VALUES = (
    "model",
    "t_max",
    "tol",
    "gamma",
    "r_esc",
    "r_far",
    "sections",
    "snapshots",
    "follow",
    "noise",
    "noise_strength",
    "kick_interval",
    "continue_settled",
    "seed",
    "batch_size",
    "tangent",
)


@dataclass(frozen=True, eq=False)
class Plan:
    """Plan(model, t_max, tol, gamma, r_esc, ..., scheduler=None): one scene as the engine integrates it.

    The first fields are the scene's values (:data:`SCENE_VALUES`: the system object, t_max and the tolerance,
    γ, r_esc and r_far, the section window, snapshot times, follow radii, noise, ...); ``scheduler`` names a
    registered scheduler (None: :func:`hhscatter.integrate.schedulers.select` picks one). The rest is derived
    in construction (``tangent``: the state carries the tangent dynamics,
    :func:`hhscatter.integrate.events.tangent_equations`): ``clock_targets`` ((orbit time, action), ...), ``far_radius``, ``follow_radii``,
    ``layout`` (:class:`hhscatter.integrate.events.Layout`), ``events`` (the
    :class:`hhscatter.integrate.events.EventSpec` tuple, callback order), ``two_phase``. :meth:`replace` gives
    a plan with some values changed (derived again).

    Examples
    --------
    >>> from hhscatter.scene.scene import Scene
    >>> p = plan_of(Scene(energy=0.2, n=10, gamma=0.01))
    >>> p.scheduler, [e.name for e in p.events], p.layout.clock
    ('stream', ['closure', 'far', 'resc', 'clock'], 4)
    >>> p.replace(scheduler="epochs").clock_targets   # the epochs end orbits at t_max themselves
    ()
    """

    model: Any
    t_max: float
    tol: float
    gamma: float
    r_esc: float
    r_far: float | None = None
    sections: Any = None
    snapshots: tuple = ()
    follow: Any = None
    noise: Any = None
    noise_strength: float = 0.0
    kick_interval: float | None = None
    continue_settled: bool = False
    seed: int = 0
    batch_size: int | None = None
    tangent: bool = False
    scheduler: str | None = None
    clock_targets: tuple = field(init=False)
    far_radius: float = field(init=False)
    follow_radii: tuple = field(init=False)
    layout: Layout = field(init=False)
    events: tuple = field(init=False)
    two_phase: bool = field(init=False)
    _cache: dict = field(init=False, repr=False)

    def __post_init__(self):
        put = object.__setattr__
        if self.scheduler is None:
            put(self, "scheduler", select(self))
        elif self.scheduler not in SCHEDULERS:
            raise ValueError(f"scheduler must be one of {sorted(SCHEDULERS)}, got {self.scheduler!r}")
        put(self, "clock_targets", events.clock_targets(self, censor=SCHEDULERS[self.scheduler].clock_censors))
        put(self, "far_radius", events.far_radius(self))
        put(self, "follow_radii", events.follow_radii(self) if self.follow is not None else ())
        put(self, "layout", events.layout(self))
        put(self, "events", events.scene_events(self))
        put(self, "two_phase", SCHEDULERS[self.scheduler].clock_censors and events.two_phase(self))
        put(self, "_cache", {})

    @property
    def kind(self) -> type:
        """The scheduler class (:data:`hhscatter.integrate.schedulers.SCHEDULERS`)."""
        return SCHEDULERS[self.scheduler]

    def __getstate__(self):
        """A plan pickles as what it holds, derived values included, without its memo (``cached``): a run
        pickles each scene's plan once and every worker process unpickles it as it is."""
        return {**self.__dict__, "_cache": {}}

    def replace(self, **values) -> Plan:
        """replace(**values) -> the plan with these values changed, everything derived again."""
        return dataclasses.replace(self, **values)

    def cached(self, key, make):
        """cached(key, make) -> ``make()``, computed once per plan and key (per-plan memo of derived values)."""
        c = self._cache
        if key not in c:
            c[key] = make()
        return c[key]


def plan_of(scene, scheduler=None) -> Plan:
    """plan_of(scene, scheduler=None) -> Plan: the scene's plan (``scene`` itself if it is one).

    ``scene``: any object with the attributes of :data:`SCENE_VALUES` (a :class:`hhscatter.scene.scene.Scene`);
    ``scheduler``: a registered scheduler's name (default: the one that applies).

    Examples
    --------
    >>> from hhscatter.scene.scene import Scene
    >>> plan_of(Scene(energy=0.2, n=10, snapshots=(0.0, 1.0))).scheduler
    'epochs'
    """
    if isinstance(scene, Plan):
        return scene if scheduler is None else scene.replace(scheduler=scheduler)
    return Plan(**{k: getattr(scene, k) for k in SCENE_VALUES}, scheduler=scheduler)


__all__ = ["Plan", "SCENE_VALUES", "plan_of"]
