"""Batch Taylor engine: ``run_chunk(scene, ics, traj_ids) -> ChunkResult``.

One block of orbits runs on one ``heyoka.taylor_adaptive_batch`` whose
events come from :mod:`hhscatter.integrate.events` (declared there once, as data). The
same rules (:class:`LaneRules`) drive the scalar reference driver
:func:`simulate_orbit` (long double, real128) used by the tests, the
benchmarks and the stress cases.

Lane schedulers, chosen by the scene's plan
-------------------------------------------
A scene is integrated through its plan (:mod:`hhscatter.integrate.plan`), which names a registered scheduler
(:mod:`hhscatter.integrate.schedulers`; the docs page "Adding a scheduler"). The stream and the epochs are
below; the noise scheduler (:mod:`hhscatter.integrate.noise`) runs epochs of one kick interval.

*Stream* (scenes without snapshots). heyoka's batch ``propagate_until``
returns for all lanes when one lane stops, and a return costs more than a
short orbit, so an orbit's end never stops the propagation: its event
callback records the outcome and loads the next initial condition into the
lane. Callbacks cannot change a lane's clock, so an orbit's time is the lane
time minus its start, both double-length (hi, lo); TwoSum keeps the
difference exact to ~2⁻¹⁰⁶ of the lane time, so orbit times do not depend on
how orbits share lanes. One case remains: an orbit time whose exact value is
a tie (halfway between two doubles; sums of steps often are) would round by
that ~2⁻¹⁰⁶ residue, which depends on the lane's start. Orbit times within
2⁻³⁰ of a gap of a tie round to even (:func:`_tie_to_even`), so they too are
the same in every lane.
Censoring is the clock's: σ = (t_max − t)/G, set at load and integrated with
the orbit, is a terminal event at t_max in the orbit's own time (its steps
and root do not depend on the lane's history; σ ∈ [0, 1] adds nothing to
the step-size control: the same steps, measured). No propagation bound ever
clamps a step: a bound (lane start + t_max) used to, and the censored state,
and the root of any event in a step clamped by an earlier orbit's stale
bound, then depended on when the lane's earlier orbits ended (the chunk
size). A chunk is one ``propagate_until`` call, so every orbit's
steps are exactly those it has alone.

*Epochs* (scenes with energy snapshots). A step callback in Python on every
step, which snapshots used to need, cost more than the integration. Here all
lanes advance together in epochs of length P, each one call of
``propagate_grid`` whose grid holds every lane's snapshot times: heyoka's
compiled dense output evaluates them, energies are computed in bulk in numpy,
and no Python runs per step or per snapshot. Every epoch starts with every
lane clock reset to 0, orbits start only at epoch starts, and an orbit that
ends mid-epoch leaves its lane parked at the origin (a fixed point: one step)
until the epoch ends. An orbit's time is its epoch count times P plus the
lane time, and its steps are cut only at multiples of P of its own time, so
results do not depend on chunking, lanes or batch size either.

Dissipative escapes end at the system's no-return radius R(E0) rather than r_far (:func:`_no_return`: the
same tables, bit for bit, in fewer steps).

Everything else is the same in both: the events and outcome rules of
:mod:`hhscatter.integrate.events`, whose roots end heyoka's step exactly (terminal
events with callbacks), so event states and times are the integrator's own.
A process compiles a scene's integrator once and reuses it for its later
chunks, reset to a new one's state (:func:`_batch_integrator`).
"""

from __future__ import annotations

# the engine's modules, by concern (hhscatter.integrate's docstring): this module gathers their public names
from hhscatter.integrate.batch import PROGRESS_EVERY
from hhscatter.integrate.chunk import run_chunk, scheduler
from hhscatter.integrate.events import CENSORED, ESCAPED, OUTCOMES, SETTLED, STOPPED
from hhscatter.integrate.lanes import LaneRules
from hhscatter.integrate.plan import Plan, plan_of
from hhscatter.integrate.reference import OrbitResult, simulate_orbit, state_at
from hhscatter.integrate.results import ChunkResult
from hhscatter.integrate.schedulers import SCHEDULERS, Scheduler, register

__all__ = [
    "PROGRESS_EVERY",
    "Plan",
    "plan_of",
    "SCHEDULERS",
    "Scheduler",
    "register",
    "LaneRules",
    "run_chunk",
    "simulate_orbit",
    "state_at",
    "scheduler",
    "ChunkResult",
    "OrbitResult",
    "OUTCOMES",
    "ESCAPED",
    "SETTLED",
    "CENSORED",
    "STOPPED",
]
