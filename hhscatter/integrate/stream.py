"""The stream scheduler (scenes without snapshots): the next orbit is loaded in the callback that ends one."""

from __future__ import annotations

import numpy as np

from hhscatter.integrate.batch import _batch_integrator, _check, _no_snapshots
from hhscatter.integrate.events import ESCAPED, SETTLED, log_stretch
from hhscatter.integrate.lanes import LIVE, RERUN, _bind
from hhscatter.integrate.orbit_time import _orbit_time
from hhscatter.integrate.schedulers import Scheduler, register

STREAM_BATCH = 8  # lanes of the stream scheduler (measured: 14 % less per lane-step than 4)
_NO_BOUND = 1e15  # propagation bound of lanes whose orbits the clock ends at t_max (never reached)


@register
class _Stream(Scheduler):
    """Stream scheduler: the next orbit is loaded in the callback that ends one."""

    name = "stream"
    priority = 90  # the scheduler of every scene no other claims
    batch_size = STREAM_BATCH
    clock_censors = True

    @classmethod
    def applies(cls, plan) -> bool:
        return True

    @classmethod
    def integrate(cls, plan, batch_size, ics, traj_ids, *, products=False, **config):
        """The chunk in one phase, or two (:attr:`hhscatter.integrate.plan.Plan.two_phase`: a window that opens
        late): the first without the section event, the orbits alive at t_from handed on to a second integrator
        that has it (:class:`_SecondPhase`)."""
        phases = plan.two_phase
        # the inlined handlers serve scenes with no section event in this integrator and no follow
        inlined = plan.follow is None and (plan.sections is None or phases)
        without = ("section",) if phases else ()
        with _batch_integrator(plan, batch_size, without=without, products=products) as (ta, specs, layout):
            lanes = cls(plan, ta, layout, ics, traj_ids, inlined=inlined, migrate_at_open=phases, **config)
            _bind(ta, specs, lanes, lanes.handlers)
            try:
                n_returns, n_steps, snaps = lanes.run()
            finally:
                lanes.close()  # the integrator goes back to the cache: no view of it stays here
        if phases and lanes.migrants:  # second phase: the orbits alive at t_from, with the section event
            with _batch_integrator(plan, batch_size, products=products) as (ta2, specs2, _):
                second = _SecondPhase(plan, ta2, layout, lanes, late=config.get("late"))
                _bind(ta2, specs2, second)
                try:
                    r2, s2, _ = second.run()
                finally:
                    second.close()
            n_returns, n_steps = n_returns + r2, n_steps + s2
        return lanes, n_returns, n_steps, snaps

    def __init__(self, plan, ta, layout, ics, traj_ids=None, *, inlined=False, **config):
        """``inlined``: serve the hot rules by the lean closures of :meth:`_inlined_handlers` (plain scenes: no
        section event in this integrator, no follow); ``config``: :class:`Scheduler`'s."""
        super().__init__(plan, ta, layout, ics, traj_ids, **config)
        # the lane time at which the lane's orbit started (double-length)
        self.start_hi, self.start_lo = np.zeros(self.B), np.zeros(self.B)
        # the lane's orbit's last outward r_esc crossing (dissipative scenes, inlined rules): whether there is
        # one (``has_out``), its lane time (double-length) and its state (x, y, px, py of lane j at 4j..4j+3)
        self.has_out = np.zeros(self.B, dtype=np.uint8)
        self.out_hi, self.out_lo, self.out_state = np.zeros(self.B), np.zeros(self.B), np.zeros(4 * self.B)
        self.out_stretch = np.zeros(self.B)  # ... and its Λ (the tangent dynamics)
        # bound of the running propagate_until call: none for live lanes (the clock censors at t_max)
        self.bound = np.zeros(self.B)
        if not any(a == "censor" for _, a in self.targets):
            raise RuntimeError("internal error: a stream scene without the clock's censor target")
        self.t_off = [0.0] * self.B  # orbit time at which the lane's orbit entered this integrator
        self.inlined = inlined
        #: {rule: handler} that replace the methods' (empty: the methods serve every rule), and the loader of the
        #: next orbit that goes with them
        self.handlers, self.loader = self._inlined_handlers() if inlined else ({}, self.load_next)

    def _inlined_handlers(self):
        """Lean closures for the hot handlers of plain scenes (no section event, no follow): ({rule: handler},
        the loader of the next orbit they share).

        The same rules as the methods of :class:`LaneRules`, with heyoka's callback signature (ta, direction,
        lane): each is its event's callback itself (:func:`hhscatter.integrate.lanes._bind`). Per orbit end no Python container is made: the
        integrator's state and lane times, the initial conditions and the chunk's records are read and written
        through flat memoryviews (one float at a time), an orbit's end is kept as lane times (orbit times are
        computed once per chunk, :meth:`orbit_times`), and the last outward r_esc crossing of a dissipative
        orbit as a lane time and a state in per-lane arrays. (Measured: lists, tuples, ``.item`` and
        ``tolist`` per orbit, and the garbage collections the containers set off, were most of the engine's
        cost above a minimal driver.)
        """
        B = self.B
        orbit = self.orbit
        s = memoryview(self.state.reshape(-1))  # s[i * B + lane]: state variable i of the lane
        hi, lo = memoryview(self.time_hi), memoryview(self.time_lo)
        sh, sl = memoryview(self.start_hi), memoryview(self.start_lo)
        has, ohi, olo, ost = (memoryview(a) for a in (self.has_out, self.out_hi, self.out_lo, self.out_state))
        out, ehi, elo, shk, slk, timed = (
            memoryview(a)
            for a in (self.outcome, self.end_hi, self.end_lo, self.start_hi_of, self.start_lo_of, self.lane_timed)
        )
        end = memoryview(self.end_state.reshape(-1))  # end[4k + i]
        ics = memoryview(self.ics.reshape(-1))  # ics[4k + i]
        # the tangent dynamics (None without): δq(0) per orbit (tan[4k + i]), the slots of δq_i (ua + i B) of a
        # lane, Λ (lnorm of δq) at each orbit's end (est) and at the lane's last outward r_esc crossing (ostr)
        tan = memoryview(self.tan0) if self.tan0 is not None else None
        ua, lnorm = (self._tan_at, log_stretch) if tan is not None else (0, None)
        ua1, ua2, ua3 = ua + B, ua + 2 * B, ua + 3 * B
        est, ostr = memoryview(self.end_stretch), memoryview(self.out_stretch)
        b1, b2, b3 = B, 2 * B, 3 * B
        n, progress, reset = self.n, self.progress, self.ta.reset_cooldowns
        # a two-phase scene's first phase has the clock (to hand orbits on at t_from, and t_max)
        clock, phase, clock_i = self.layout.clock, self.phase, self.clock_i
        sc = clock * B if clock is not None else 0
        sigma0 = self.targets[0][0] / self.clock_scale
        r_s2 = self.r_s * self.r_s
        late = self.late
        orbit_time = _orbit_time
        nxt = self.next
        escaped, settled, rerun = ESCAPED, SETTLED, RERUN

        def load_next_at(lane, h, el):
            """Load the next orbit into ``lane``, whose time is (h, el) now; park the lane if none is left."""
            nonlocal nxt
            k = nxt
            if k >= n:
                orbit[lane] = -1
                self.next = n
                return False
            nxt = k + 1
            orbit[lane] = k
            has[lane] = 0
            if progress is not None:
                self.tick()
            j = 4 * k
            s[lane] = ics[j]
            s[b1 + lane] = ics[j + 1]
            s[b2 + lane] = ics[j + 2]
            s[b3 + lane] = ics[j + 3]
            if tan is not None:
                s[ua + lane] = tan[j]
                s[ua1 + lane] = tan[j + 1]
                s[ua2 + lane] = tan[j + 2]
                s[ua3 + lane] = tan[j + 3]
            if clock is not None:
                s[sc + lane] = sigma0
                clock_i[lane] = 0
                phase[lane] = LIVE
            sh[lane] = h
            sl[lane] = el
            reset(lane)
            return True

        def load_next(lane):
            return load_next_at(lane, hi[lane], lo[lane])

        def end_here(lane, code):
            """The orbit of ``lane`` ends where the lane is now (its time and state)."""
            k = orbit[lane]
            a, el = hi[lane], lo[lane]
            out[k] = code
            timed[k] = 1
            ehi[k] = a
            elo[k] = el
            shk[k] = sh[lane]
            slk[k] = sl[lane]
            j = 4 * k
            end[j] = s[lane]
            end[j + 1] = s[b1 + lane]
            end[j + 2] = s[b2 + lane]
            end[j + 3] = s[b3 + lane]
            if tan is not None:
                est[k] = lnorm(s[ua + lane], s[ua1 + lane], s[ua2 + lane], s[ua3 + lane])
            return load_next_at(lane, a, el)  # the next orbit starts at the time this one ends

        def end_out(lane, code):
            """The orbit of ``lane`` ends at its last outward r_esc crossing."""
            k = orbit[lane]
            out[k] = code
            timed[k] = 1
            ehi[k] = ohi[lane]
            elo[k] = olo[lane]
            shk[k] = sh[lane]
            slk[k] = sl[lane]
            j, q = 4 * k, 4 * lane
            end[j] = ost[q]
            end[j + 1] = ost[q + 1]
            end[j + 2] = ost[q + 2]
            end[j + 3] = ost[q + 3]
            if tan is not None:
                est[k] = ostr[lane]
            return load_next(lane)

        def on_escape(ta, d, lane):
            # end_here(lane, ESCAPED) and load_next_at written out: the hottest path (conservative scenes)
            nonlocal nxt
            k = orbit[lane]
            if k < 0:
                return True
            a, el = hi[lane], lo[lane]
            out[k] = escaped
            timed[k] = 1
            ehi[k] = a
            elo[k] = el
            shk[k] = sh[lane]
            slk[k] = sl[lane]
            j = 4 * k
            end[j] = s[lane]
            end[j + 1] = s[b1 + lane]
            end[j + 2] = s[b2 + lane]
            end[j + 3] = s[b3 + lane]
            if tan is not None:
                est[k] = lnorm(s[ua + lane], s[ua1 + lane], s[ua2 + lane], s[ua3 + lane])
            k = nxt
            if k >= n:
                orbit[lane] = -1
                self.next = n
                return False
            nxt = k + 1
            orbit[lane] = k
            if progress is not None:
                self.tick()
            j = 4 * k
            s[lane] = ics[j]
            s[b1 + lane] = ics[j + 1]
            s[b2 + lane] = ics[j + 2]
            s[b3 + lane] = ics[j + 3]
            if tan is not None:
                s[ua + lane] = tan[j]
                s[ua1 + lane] = tan[j + 1]
                s[ua2 + lane] = tan[j + 2]
                s[ua3 + lane] = tan[j + 3]
            if clock is not None:
                s[sc + lane] = sigma0
                clock_i[lane] = 0
                phase[lane] = LIVE
            sh[lane] = a
            sl[lane] = el
            reset(lane)
            return True

        def on_resc(ta, d, lane):
            if orbit[lane] >= 0:
                if d > 0:
                    has[lane] = 1
                    ohi[lane] = hi[lane]
                    olo[lane] = lo[lane]
                    q = 4 * lane
                    ost[q] = s[lane]
                    ost[q + 1] = s[b1 + lane]
                    ost[q + 2] = s[b2 + lane]
                    ost[q + 3] = s[b3 + lane]
                    if tan is not None:
                        ostr[lane] = lnorm(s[ua + lane], s[ua1 + lane], s[ua2 + lane], s[ua3 + lane])
                else:
                    has[lane] = 0
            return True

        def on_closure(ta, d, lane):
            if orbit[lane] < 0:
                return True
            x, y = s[lane], s[b1 + lane]
            if x * x + y * y <= r_s2:  # events.closure_rule, inlined
                return end_here(lane, settled)
            return end_out(lane, escaped) if has[lane] else True

        def on_far(ta, d, lane):
            if orbit[lane] < 0:
                return True
            if not has[lane]:  # unreachable: r_far > r_esc; kept as a guard
                raise RuntimeError("orbit reached r_far without crossing r_esc")
            if late is not None:
                t = orbit_time(hi[lane], lo[lane], sh[lane], sl[lane])
                if late(t, s[lane], s[b1 + lane], s[b2 + lane], s[b3 + lane]):
                    return end_out(lane, rerun)
            return end_out(lane, escaped)

        handlers = {"escape": on_escape, "resc": on_resc, "closure": on_closure, "far": on_far}
        return handlers, load_next

    def last_out_of(self, lane):
        if not self.inlined:
            return self.last_out[lane]
        if not self.has_out[lane]:
            return None
        t = _orbit_time(*(float(a[lane]) for a in (self.out_hi, self.out_lo, self.start_hi, self.start_lo)))
        stretch = float(self.out_stretch[lane]) if self.tan0 is not None else None
        return t, tuple(self.out_state[4 * lane : 4 * lane + 4].tolist()), stretch

    def elapsed(self, lane):
        """Orbit time of ``lane`` now: the double nearest (hi + lo) − (hi0 + lo0), via TwoSum."""
        r = _orbit_time(
            self.time_hi.item(lane), self.time_lo.item(lane), self.start_hi.item(lane), self.start_lo.item(lane)
        )
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
        self.start_hi[lane], self.start_lo[lane] = self.time_hi[lane], self.time_lo[lane]
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
        for name in (*self.RECORDS, "sec_rows", "cross_rows"):
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
