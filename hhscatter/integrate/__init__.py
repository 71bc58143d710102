"""Integration: events declared as data and the batch Taylor engine that decides outcomes at their exact roots.

One module per concern (in the manner of SciPy's ``integrate/_ivp``):

| module | concern |
|---|---|
| `plan` | a scene's `Plan`: what the engine reads from it, frozen once, and what it derives (scheduler, layout, events) |
| `schedulers` | the scheduler contract (`Scheduler`) and registry (`SCHEDULERS`, `register`) |
| `events` | the events and outcome rules of a scene, as data |
| `integrators` | heyoka's batch and scalar integrators built from those events (the only heyoka events) |
| `lanes` | the lane-rules contract: `LaneRules`, the rules as event handlers per lane, their callbacks |
| `batch` | lanes of one batch integrator, and the per-process cache of compiled integrators |
| `stream` | the stream scheduler (no snapshots): an orbit's end loads the next in its callback |
| `epochs` | the epoch scheduler (snapshots): all lanes advance together, `propagate_grid` |
| `noise` | the noise scheduler (scenes with `[noise]`): epochs of one kick interval, vectorised Ornstein–Uhlenbeck kicks |
| `noise_reference` | an independent numpy Langevin integrator (OBABO), the noise scheduler's reference |
| `orbit_time` | an orbit's time on a stream lane (TwoSum, near-ties to even) |
| `chunk` | `run_chunk`: one block of orbits on its plan's scheduler, its reruns and results |
| `rerun` | orbits integrated again: the no-return rule's late ones, those an event-detection failure hit |
| `results` | a chunk's rows (`ChunkResult`) |
| `reference` | the reference driver: one orbit on heyoka's scalar integrator, any precision |
| `heyoka_log` | heyoka's log captured, event-detection failures counted |
| `engine` | the public names of all of these, gathered (`run_chunk`, `simulate_orbit`, ...) |

The life of an orbit in a lane, in one vocabulary (the method names of the modules above):

* **load** — an orbit enters a lane: its initial condition (or, in a second phase, its state, orbit time and
  rule state), its rule state and the lane's event cooldowns (``load_orbit``; ``load_next`` takes the next
  orbit of the chunk, or parks the lane);
* **record** — the orbit's outcome, end time and end state are written (``record``);
* **end** — the outcome is known: record it, then release the lane, unless the scene follows the orbit on
  (``end``; the stream's inlined handlers ``end_at`` a given time and state, ``end_here`` where the lane is);
* **commit** — the orbit's pending table rows go to the output (``commit``, ``commit_rows``);
* **release** — the orbit needs nothing more: commit its rows, then load the next orbit or park (``release``);
* **park** — no orbit is left for the lane: it holds still (the stream) or sits at the origin (the epochs).

The engine reads a scene only through its plan (:func:`hhscatter.integrate.plan.plan_of`); it imports neither
:mod:`hhscatter.scene` nor :mod:`hhscatter.model` (the plan holds the system object), and it is the only part of
the package that imports heyoka (the system builds its expressions with the heyoka module the engine hands it).
Both rules are checked on the package's import graph, read from the source.
"""
