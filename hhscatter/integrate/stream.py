"""The stream scheduler (scenes without snapshots): the next orbit is loaded in the callback that ends one."""

from __future__ import annotations

import numpy as np

from hhscatter.integrate.batch import _BatchRules, _check, _no_snapshots
from hhscatter.integrate.events import ESCAPED, SETTLED
from hhscatter.integrate.lanes import LIVE, RERUN
from hhscatter.integrate.orbit_time import _orbit_time

STREAM_BATCH = 8  # lanes of the stream scheduler (measured: 14 % less per lane-step than 4)
_NO_BOUND = 1e15  # propagation bound of lanes whose orbits the clock ends at t_max (never reached)


class _Stream(_BatchRules):
    """Stream scheduler: the next orbit is loaded in the callback that ends one."""

    def __init__(self, scene, ta, layout, ics, *, inlined=False, **config):
        """``inlined``: serve the hot rules by the lean closures of :meth:`_inlined_handlers` (plain scenes: no
        section event in this integrator, no follow); ``config``: :class:`_BatchRules`'s."""
        super().__init__(scene, ta, layout, ics, **config)
        self.start_hi = [0.0] * self.B
        self.start_lo = [0.0] * self.B
        # bound of the running propagate_until call: none for live lanes (the clock censors at t_max)
        self.bound = np.zeros(self.B)
        if not any(a == "censor" for _, a in self.targets):
            raise RuntimeError("internal error: a stream scene without the clock's censor target")
        self.t_off = [0.0] * self.B  # orbit time at which the lane's orbit entered this integrator
        #: {rule: handler} that replace the methods' (empty: the methods serve every rule), and the loader of the
        #: next orbit that goes with them
        self.handlers, self.loader = self._inlined_handlers() if inlined else ({}, self.load_next)

    def _inlined_handlers(self):
        """Lean closures for the hot handlers of plain scenes (no section event, no follow): ({rule: handler},
        the loader of the next orbit they share).

        The same rules as the methods of :class:`LaneRules`, with the per-orbit
        Python cut to a few list operations (measured: the generic chain of
        method calls cost ~3 µs per orbit, more than half the integration of a
        conservative orbit at E = 0.27).
        """
        elapsed, end_at, end_here, load_next, cols = self._inlined_orbit_steps()
        orbit, last_out = self.orbit, self.last_out
        r_s2 = self.r_s * self.r_s

        def on_escape(lane, d):
            if orbit[lane] < 0:
                return True
            return end_here(lane, ESCAPED)

        def on_resc(lane, d):
            if orbit[lane] >= 0:
                last_out[lane] = (elapsed(lane), cols[lane].tolist()) if d > 0 else None
            return True

        def on_closure(lane, d):
            if orbit[lane] < 0:
                return True
            x, y, _, _ = cols[lane].tolist()
            if x * x + y * y <= r_s2:  # events.closure_rule, inlined
                return end_here(lane, SETTLED)
            out = last_out[lane]
            return end_at(lane, ESCAPED, *out) if out is not None else True

        late = self.late

        def on_far(lane, d):
            if orbit[lane] < 0:
                return True
            out = last_out[lane]
            if out is None:  # unreachable: r_far > r_esc; kept as a guard
                raise RuntimeError("orbit reached r_far without crossing r_esc")
            if late is not None and late(elapsed(lane), cols[lane].tolist()):
                return end_at(lane, RERUN, *out)
            return end_at(lane, ESCAPED, *out)

        return {"escape": on_escape, "resc": on_resc, "closure": on_closure, "far": on_far}, load_next

    def _inlined_orbit_steps(self):
        """The closures the inlined handlers share: a lane's orbit time, the end of an orbit at a given time and
        state (record, load the next), the end of an orbit where the lane is now, the loading of the next orbit
        (returns what a callback returns); state captured once, as lists, Python floats and per-lane views.
        Per orbit end (measured): the lane time is read once (an orbit that ends where the lane is
        ends at the time the next starts), the state through ``cols[lane]`` (a third of ``state[:4, lane]``)."""
        orbit, last_out = self.orbit, self.last_out
        hi, lo, starts_hi, starts_lo = self.time_hi, self.time_lo, self.start_hi, self.start_lo
        st, ics, ta, cols = self.state, self.ics, self.ta, self.cols
        outcomes, t_ends, end_states = self.outcome, self.t_end, self.end_state
        n = self.n
        progress = self.progress
        reset = ta.reset_cooldowns
        # a two-phase scene's first phase has the clock (to hand orbits on at t_from, and t_max)
        clock, phase, clock_i = self.layout.clock, self.phase, self.clock_i
        sigma0 = self.targets[0][0] / self.clock_scale

        hi_, lo_ = hi.item, lo.item  # Python floats: numpy scalar arithmetic costs ~5× more
        orbit_time = _orbit_time

        def elapsed(lane):
            return orbit_time(hi_(lane), lo_(lane), starts_hi[lane], starts_lo[lane])

        counter = [self.next]

        def load_next_at(lane, h, el):
            """Load the next orbit into ``lane``, whose time is (h, el) now."""
            k = counter[0]
            if k >= n:
                orbit[lane] = -1
                self.next = n
                return False
            counter[0] = k + 1
            orbit[lane] = k
            last_out[lane] = None
            if progress is not None:
                self.tick()
            c = cols[lane]
            c[0], c[1], c[2], c[3] = ics[k]  # four scalar writes: half the cost of converting the list
            if clock is not None:
                st[clock, lane] = sigma0
                clock_i[lane] = 0
                phase[lane] = LIVE
            starts_hi[lane] = h
            starts_lo[lane] = el
            reset(lane)
            return True

        def load_next(lane):
            return load_next_at(lane, hi_(lane), lo_(lane))

        def end_at(lane, outcome, t, state):
            k = orbit[lane]
            outcomes[k], t_ends[k], end_states[k] = outcome, t, state
            return load_next(lane)

        def end_here(lane, outcome):
            k = orbit[lane]
            a, el = hi_(lane), lo_(lane)
            outcomes[k] = outcome
            t_ends[k] = orbit_time(a, el, starts_hi[lane], starts_lo[lane])  # elapsed(lane), lane time read once
            end_states[k] = cols[lane].tolist()
            return load_next_at(lane, a, el)

        return elapsed, end_at, end_here, load_next, cols

    def elapsed(self, lane):
        """Orbit time of ``lane`` now: the double nearest (hi + lo) − (hi0 + lo0), via TwoSum."""
        r = _orbit_time(self.time_hi.item(lane), self.time_lo.item(lane), self.start_hi[lane], self.start_lo[lane])
        # + the orbit time at which it entered this integrator (0 but in a second phase)
        return r + self.t_off[lane]

    def load_next(self, lane):
        """Put the next orbit into ``lane``; park the lane if none is left.

        Returns what a callback must return: False (stop the propagation, so that
        the parked lane holds still) when the lane is parked.
        """
        k = self.next
        if k >= self.n:
            self.orbit[lane] = -1
            if self.layout.gate is not None:
                self.set_gate(lane, 0.0)
            return False
        self.next = k + 1
        self.load_orbit(lane, k)
        self.start_hi[lane], self.start_lo[lane] = self.time_hi.item(lane), self.time_lo.item(lane)
        return True

    def release(self, lane):
        self.commit_rows(lane)
        return self.loader(lane)

    def close(self):
        super().close()
        self.handlers, self.loader = {}, None  # the closures refer back to the lanes: free them now

    def run(self):
        B, ta, bound = self.B, self.ta, self.bound
        for lane in range(B):
            self.loader(lane)
        n_returns = n_steps = 0
        while True:
            for lane in range(B):
                # parked lanes hold still at their current time
                bound[lane] = _NO_BOUND if self.orbit[lane] >= 0 else self.time_hi[lane]
            if all(k < 0 for k in self.orbit):
                break
            ta.propagate_until(bound)
            n_returns += 1
            n_steps += _check(ta, self)  # once per return (a handful per chunk)
        return n_returns, n_steps, _no_snapshots()


class _SecondPhase(_Stream):
    """The second phase of a two-phase stream scene: the orbits handed on at t_from, with the
    section event compiled in. Loads a migrant's state, orbit time and rule state instead of an
    initial condition; shares the outcome arrays and rows with the first phase."""

    def __init__(self, scene, ta, layout, first, *, late=None):
        self.migrants_in = first.migrants
        # (no progress: the first phase reported these orbits already)
        super().__init__(scene, ta, layout, np.zeros((len(first.migrants), 4)), late=late)
        for name in ("outcome", "t_end", "end_state", "sec_rows", "cross_rows"):
            setattr(self, name, getattr(first, name))

    def load_orbit(self, lane, j):
        k, state, t_mig, clock_i, last_out, phase = self.migrants_in[j]
        self.state[:4, lane] = state
        self.start_orbit(lane, k)
        self.last_out[lane], self.phase[lane] = last_out, phase
        self.t_off[lane] = t_mig
        self.set_gate(lane, 1.0)
        self.clock_i[lane] = clock_i
        targets = self.targets
        self.set_clock(lane, (targets[clock_i][0] - t_mig) / self.clock_scale if clock_i < len(targets) else 1.0)
        self.ta.reset_cooldowns(lane)
