"""Lanes of one batch integrator: the per-process integrator cache and the part both schedulers share."""

from __future__ import annotations

import collections
import contextlib
import math
import threading

import numpy as np

from hhscatter.integrate import events, integrators
from hhscatter.integrate.lanes import CONTINUING, LaneRules, _Callback, _unbind
from hhscatter.integrate.orbit_time import _orbit_times

PROGRESS_EVERY = 1024  # orbits between progress reports from inside a chunk


_FREE = collections.OrderedDict()  # batch_key -> integrators that finished a chunk, ready for the next one
_FREE_LOCK = threading.Lock()  # (a Dask worker may run chunks in threads)
_FREE_KEYS = 4  # distinct compiled systems kept per process (a grid of r_esc values compiles one each)


@contextlib.contextmanager
def _batch_integrator(scene, batch_size, without=(), products=False):
    """_batch_integrator(scene, batch_size, without=(), products=False) -> context manager yielding (ta, specs,
    layout).

    One compiled batch integrator per worker process and scene (:func:`hhscatter.integrate.integrators.batch_key`),
    reused across chunks instead of a new ``taylor_adaptive_batch`` per chunk (measured: ~6 ms and a
    JIT lookup each). A reused integrator is reset to what a new one is: time 0 (both parts of the
    double-length clock), state 0, the scene's parameters (γ; gates closed), no event cooldowns;
    heyoka's step depends on nothing else, so results are bit-identical (tested). An integrator in
    use is out of the cache; the handlers are unbound on return.
    """
    key, specs, lay = integrators.batch_key(scene, batch_size, without=without, products=products)
    with _FREE_LOCK:
        free = _FREE.get(key)
        ta = free.pop() if free else None
    if ta is None:
        ta, specs, lay = integrators.build_batch(scene, batch_size, _Callback, without=without, products=products)
    else:
        zeros = np.zeros(batch_size)
        ta.set_dtime(zeros, zeros)
        ta.state[:] = 0.0
        pars = integrators.batch_pars(scene, lay, batch_size, without)
        if len(pars):
            ta.pars[:] = pars
        ta.reset_cooldowns()
    try:
        yield ta, specs, lay
    finally:
        _unbind(ta)
        with _FREE_LOCK:
            _FREE.setdefault(key, []).append(ta)
            _FREE.move_to_end(key)
            while len(_FREE) > _FREE_KEYS:
                _FREE.popitem(last=False)


class _BatchRules(LaneRules):
    """Lanes of one batch integrator: the part shared by both schedulers."""

    def __init__(
        self,
        scene,
        ta,
        layout,
        ics,
        *,
        count_steps=False,
        progress=None,
        late=None,
        migrate_at_open=False,
        open_late=None,
    ):
        """``count_steps``: the epoch loop reads every lane's result (``ChunkResult.n_steps``); ``progress``: f(k)
        after every PROGRESS_EVERY orbits loaded; ``late``: the no-return rule's test (:attr:`LaneRules.late`);
        ``migrate_at_open``: the first phase of a two-phase scene (orbits handed on when the window opens);
        ``open_late``: None, or a bool per orbit: its section window opens at T_INITIAL (the scene has a clock)."""
        self.ta = ta
        self.B = ta.batch_size
        self.setup(scene, layout, self.B)
        self.late = late
        self.migrate_at_open = migrate_at_open
        if open_late is not None:
            if layout.clock is None:
                raise RuntimeError("internal error: an orbit's window opens late in a scene without a clock")
            self.open_late = open_late.tolist()
        self.state = ta.state  # live views into the integrator
        self.cols = [self.state[:4, lane] for lane in range(self.B)]  # (x, y, px, py) of each lane
        self.pars = ta.pars if layout.n_pars else None
        self.gate_live = layout.gate is not None and layout.gate < len(ta.pars)
        self.time_hi, self.time_lo = ta.dtime
        self.ics = np.ascontiguousarray(ics, dtype=float)
        if not (self.state.flags.c_contiguous and (self.pars is None or self.pars.flags.c_contiguous)):
            raise RuntimeError("internal error: the integrator's state or parameters are not one contiguous block")
        # flat memoryviews (one element written at a time, no numpy scalar or index tuple per write):
        # state variable i of a lane at i * B + lane, initial condition k at 4k .. 4k + 3
        self._s, self._ic = memoryview(self.state.reshape(-1)), memoryview(self.ics.reshape(-1))
        self._p = memoryview(self.pars.reshape(-1)) if self.gate_live else None
        self._gate_at = layout.gate * self.B if self.gate_live else 0
        self._clock_at = layout.clock * self.B if layout.clock is not None else 0
        # the tangent dynamics: each orbit's δq(0) = ν u(0) (k at 4k .. 4k + 3), the slots of δq in the state
        self.tan0 = None
        if layout.tangent is not None:
            self.tan0 = np.ascontiguousarray(
                events.tangent_start(scene, ics) * events.TANGENT_NORM, dtype=float
            ).reshape(-1)
            self._tan_at = layout.tangent * self.B
        self.n = len(ics)
        self.next = 0
        self.t_max = scene.t_max
        self.count_steps = count_steps
        self.progress = progress
        self.ticks = 0
        self._records(self.n)

    #: the per-orbit arrays an orbit's end is written into (a second phase shares its first phase's)
    RECORDS = (
        "outcome",
        "t_end",
        "end_state",
        "end_stretch",
        "lane_timed",
        "end_hi",
        "end_lo",
        "start_hi_of",
        "start_lo_of",
    )

    def _records(self, n):
        """Preallocate what the chunk's orbits end with: ``outcome`` (int8, −1 until known), the end state
        ``end_state`` (n, 4), and the orbit time either as a number (``t_end``, by :meth:`record`) or, where
        ``lane_timed``, as the lane time at the end and at the orbit's start, double-length (``end_hi``,
        ``end_lo``, ``start_hi_of``, ``start_lo_of``: the stream's ends, whose times :meth:`orbit_times` computes
        once per chunk). No Python object is kept per orbit."""
        self.outcome = np.full(n, -1, dtype=np.int8)
        self.t_end = np.full(n, math.nan)
        self.end_state = np.zeros((n, 4))
        self.end_stretch = np.zeros(n)  # Λ at the end (the tangent dynamics; 0 without)
        self.lane_timed = np.zeros(n, dtype=np.uint8)
        self.end_hi, self.end_lo = np.zeros(n), np.zeros(n)
        self.start_hi_of, self.start_lo_of = np.zeros(n), np.zeros(n)

    def orbit_times(self) -> np.ndarray:
        """The orbit time at each orbit's end (time units), once per chunk: :meth:`record`'s, or, for the
        orbits ended by lane time, (end) − (start) of the double-length lane times (:func:`_orbit_times`)."""
        t = self.t_end.copy()
        m = self.lane_timed.astype(bool)
        if m.any():
            t[m] = _orbit_times(self.end_hi[m], self.end_lo[m], self.start_hi_of[m], self.start_lo_of[m])
        return t

    def state4(self, lane):
        return tuple(self.cols[lane].tolist())

    def set_gate(self, lane, g):
        if self.gate_live:  # (a first phase has no section event, hence no gate)
            self._p[self._gate_at + lane] = g

    def set_clock(self, lane, sigma):
        self._s[self._clock_at + lane] = sigma

    def stretch(self, lane):
        if self.tan0 is None:
            return None
        s, a, B = self._s, self._tan_at + lane, self.B
        return events.log_stretch(s[a], s[a + B], s[a + 2 * B], s[a + 3 * B])

    def record(self, lane, outcome, t, state, stretch=None):
        k = self.orbit[lane]
        self.outcome[k] = outcome
        self.t_end[k] = t
        self.lane_timed[k] = 0
        self.end_state[k] = state
        if self.tan0 is not None:
            self.end_stretch[k] = self.stretch(lane) if stretch is None else stretch

    def load_tangent(self, lane, k):
        """δq(0) = ν u(0) of orbit k (Λ = 0) into ``lane`` (the tangent dynamics)."""
        s, t, B, j, a = self._s, self.tan0, self.B, 4 * k, self._tan_at
        s[a + lane] = t[j]
        s[a + B + lane] = t[j + 1]
        s[a + 2 * B + lane] = t[j + 2]
        s[a + 3 * B + lane] = t[j + 3]

    def tick(self):
        """Report progress every PROGRESS_EVERY loaded orbits (``run_chunk(progress=...)``)."""
        self.ticks += 1
        if self.ticks >= PROGRESS_EVERY:
            self.progress(self.ticks)
            self.ticks = 0

    def close(self):
        """Drop every view of the integrator (it goes back to the cache) and every closure over these lanes."""
        self.ta = self.state = self.cols = self.pars = self.time_hi = self.time_lo = None
        self._s = self._ic = self._p = None

    def load_orbit(self, lane, k):
        """Initial condition k into ``lane`` (state, rules, cooldowns)."""
        if self.progress is not None:
            self.tick()
        s, ic, B, j = self._s, self._ic, self.B, 4 * k
        s[lane] = ic[j]
        s[B + lane] = ic[j + 1]
        s[2 * B + lane] = ic[j + 2]
        s[3 * B + lane] = ic[j + 3]
        if self.tan0 is not None:
            self.load_tangent(lane, k)
        self.start_orbit(lane, k)
        self.ta.reset_cooldowns(lane)

    def commit_rows(self, lane):
        if self.pending_sec[lane] or self.pending_cross[lane]:
            k = self.orbit[lane]
            self.commit(lane, self.t_end[k], self.phase[lane] == CONTINUING)


def _check(ta, rules):
    import heyoka as hy  # deferred: heyoka loads on first use

    steps = 0
    for lane, res in enumerate(ta.propagate_res):
        steps += res[3]
        if res[0] == hy.taylor_outcome.err_nf_state:
            if rules.tan0 is not None and not np.all(
                np.isfinite(np.asarray(rules._s)[rules._tan_at + lane :: rules.B][:4])
            ):
                raise FloatingPointError(
                    f"the tangent vector of the orbit in lane {lane} overflowed a double: its log-stretch Λ passed "
                    f"≈ 1375 (Λ is guaranteed to leave the orbit unchanged up to {events.MAX_LOG_STRETCH:g}); "
                    "a shorter t_max keeps it below"
                )
            raise FloatingPointError(
                f"non-finite state in lane {lane}; this is a bug: escaping orbits must be stopped by the "
                "engine's events"
            )
    return steps


def _no_snapshots():
    return np.empty(0, np.int64), np.empty(0), np.empty(0)
