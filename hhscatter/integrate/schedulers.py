"""The scheduler contract and its registry: how a chunk's orbits share the lanes of one batch integrator.

A scheduler is a class (:class:`Scheduler`) registered by name in :data:`SCHEDULERS`, as SciPy's
``solve_ivp`` finds its solvers in ``METHODS`` and each subclasses ``OdeSolver``. The built-ins register
themselves where they are defined: ``stream`` (:mod:`hhscatter.integrate.stream`), ``epochs``
(:mod:`hhscatter.integrate.epochs`) and ``noise`` (:mod:`hhscatter.integrate.noise`). A scene's
plan (:class:`hhscatter.integrate.plan.Plan`) names the one that integrates it: the registered scheduler of
lowest :attr:`Scheduler.priority` whose :meth:`Scheduler.applies` accepts the plan, unless the plan names
one. :func:`hhscatter.integrate.chunk.run_chunk` knows no scheduler by name: what differs between them is
declared here, as class attributes. The docs page "Adding a scheduler" walks through a new one.
"""

from __future__ import annotations

import abc

from hhscatter.integrate.batch import _batch_integrator, _BatchRules
from hhscatter.integrate.lanes import _bind

#: name -> scheduler class (:func:`register` adds one)
SCHEDULERS: dict[str, type[Scheduler]] = {}


def register(cls):
    """register(cls) -> cls: add a :class:`Scheduler` subclass to :data:`SCHEDULERS` under ``cls.name`` (a class
    decorator).

    Examples
    --------
    >>> "stream" in SCHEDULERS and "epochs" in SCHEDULERS and "noise" in SCHEDULERS
    True
    """
    if not (isinstance(cls, type) and issubclass(cls, Scheduler)) or not cls.name:
        raise TypeError(f"a scheduler is a named subclass of Scheduler, got {cls!r}")
    SCHEDULERS[cls.name] = cls
    return cls


def select(plan) -> str:
    """select(plan) -> the name of the registered scheduler of lowest priority whose ``applies(plan)`` is true."""
    for cls in sorted(SCHEDULERS.values(), key=lambda c: c.priority):
        if cls.applies(plan):
            return cls.name
    raise ValueError(f"no registered scheduler applies to this scene (registered: {sorted(SCHEDULERS)})")


class Scheduler(_BatchRules):
    """The contract of a scheduler: the lanes of one batch integrator and the loop that drives them.

    A subclass sets the class attributes below, implements :meth:`run` (and the lane access of
    :class:`hhscatter.integrate.lanes.LaneRules` that :class:`hhscatter.integrate.batch._BatchRules` leaves
    open: ``elapsed`` and ``release``), and is registered with :func:`register`. The outcome rules are the
    inherited handlers; a scheduler records each orbit's end through ``record`` (or the arrays of
    ``RECORDS``) and never builds tables itself: :func:`hhscatter.integrate.chunk.run_chunk` does, once per
    chunk.
    """

    #: the name a plan selects it by (``Plan.scheduler``)
    name: str = ""
    #: lower first: :func:`select` asks the registered schedulers in this order
    priority: int = 100
    #: lanes of its batch integrator unless the scene sets ``batch_size``
    batch_size: int = 8
    #: censors at t_max with the orbit clock (σ, a terminal event in the orbit's own time); else the scheduler
    #: ends orbits at t_max itself
    clock_censors: bool = False
    #: an orbit is the deterministic flow from its initial condition: the no-return radius may end dissipative
    #: escapes early, and an orbit hit by an event-detection failure is redone on the reference driver
    #: (:mod:`hhscatter.integrate.rerun`)
    deterministic: bool = True
    #: {rule: callable (ta, direction, lane)} bound as those events' callbacks in place of the methods
    handlers: dict = {}

    def __init__(self, plan, ta, layout, ics, traj_ids=None, **config):
        """``plan``: the scene's :class:`hhscatter.integrate.plan.Plan`; ``ta``: the batch integrator and
        ``layout`` its slots; ``ics`` (n, 4) and ``traj_ids`` (n,) the chunk's orbits; ``config``:
        :class:`hhscatter.integrate.batch._BatchRules`' (count_steps, progress, late, open_late, ...)."""
        super().__init__(plan, ta, layout, ics, **config)
        self.traj_ids = traj_ids

    @classmethod
    def applies(cls, plan) -> bool:
        """Whether this scheduler integrates ``plan``'s scene when the plan names none."""
        return False

    @abc.abstractmethod
    def run(self) -> tuple:
        """Integrate every orbit of the chunk: (propagation calls, steps, (snapshot orbit, t, energy) arrays)."""

    @classmethod
    def integrate(cls, plan, batch_size, ics, traj_ids, *, products=False, **config):
        """integrate(plan, batch_size, ics, traj_ids, products=False, **config) -> (lanes, calls, steps,
        snapshots): the chunk's orbits on one integrator of the per-process cache, the handlers bound for the
        run and unbound after it. A scheduler with more than one integrator per chunk overrides this (the
        stream's two phases)."""
        with _batch_integrator(plan, batch_size, products=products) as (ta, specs, layout):
            lanes = cls(plan, ta, layout, ics, traj_ids, **config)
            _bind(ta, specs, lanes, lanes.handlers)
            try:
                n_returns, n_steps, snaps = lanes.run()
            finally:
                lanes.close()
        return lanes, n_returns, n_steps, snaps


__all__ = ["SCHEDULERS", "Scheduler", "register", "select"]
