"""The epoch scheduler (scenes with energy snapshots): all lanes advance together; snapshots from ``propagate_grid``.

Where its time goes (measured on ``make bench-engine``'s recording scene: E0 = 0.3, γ = 0.01, snapshots every 0.5
to t = 200 and the first section crossing after t = 17, orbits living 8.4 on average, about one epoch of P = 8;
CPU per orbit against the dissipative scene on the stream, thread CPU clocks around each phase): the
``propagate_grid`` calls, heyoka's compiled propagation with the event callbacks, take 1.8–2.1× the whole bare
scene's CPU by themselves. heyoka's batch ``propagate_grid`` costs 1.4× ``propagate_until`` per lane-step with 2
grid points per epoch and 1.75× with the 17 of snapshots every 0.5 (it writes the Taylor coefficients at every step
and walks the grid lane by lane), the gated section event and its clock 1.1–1.2× more (the first-section scene on
the stream), and lanes parked until the epoch ends leave 28 % of the batch's lane-steps idle (1.44 lane-steps per
step the same orbits take on the stream). Python's
part, per epoch and per orbit, is the rest (34–37 % of the scene's CPU before it was trimmed, 26–29 % after): one
pass over the lanes per epoch (epochs closed, lanes refilled, the next epoch's grid index; lists, not per-epoch
numpy arrays), the next orbit loaded by one closure, the state checked by one reduction, the snapshot rows
gathered every :data:`SNAPSHOT_BLOCKS` epochs in bulk (about a third of that is the model's energy, ``y**3``
through ``pow``), and heyoka's per-lane results read once per epoch when steps are counted (``count_steps``).
Starting an orbit as soon as its lane is free would need a return per orbit end and per-lane grids: at most those
28 % of the compiled part are to be won, and one more ``propagate_grid`` call per orbit costs more (≈ 25 µs beyond
its steps, measured with 8 lanes). Nor can a call stop early and the lanes still mid-epoch go on:
``propagate_grid`` starts by propagating each lane to its first grid point, a double, so a lane at (hi, lo) first
steps by −lo to (hi, 0), which changes its time (and may change its state) in the last bits: the tables would no
longer be bit-identical.

Measured and not taken (heyoka 7.13): continuous output (``propagate_until(P, c_output=True)``) gives the very
values ``propagate_grid`` gives at the same times (0 of 36 000 differed), but every call compiles its evaluator
(1.4–8 ms, against ~0.25 ms for one epoch's ``propagate_grid``), and it stores the Taylor coefficients at ~650 B and
≈ 0.5 µs per lane-step (5–6× ``propagate_until`` on one long call). Shorter epochs (P = 4, 2, 1: 3.7×, 5.0×, 6.4×
the bare scene against 3.3× at P = 8) lose more to the calls than they win from parked lanes; P = 12 and 16 moved
the ratio within the machine's noise (2.85–3.14×); 16 and 32 lanes took 0.91–0.94× the CPU of 8 (hence 16). Shorter
or longer epochs change the tables in the last bits (at P = 4, 44 % of the t_end by ≥ 1 ulp).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from hhscatter.integrate import events
from hhscatter.integrate.batch import _BatchRules, _check
from hhscatter.integrate.events import CENSORED, ESCAPED, SETTLED
from hhscatter.integrate.lanes import CONTINUING, LIVE, RERUN, LaneRules
from hhscatter.integrate.schedulers import Scheduler, register

EPOCH = 8.0  # target epoch length P (time units) of the epoch scheduler
SNAPSHOT_BLOCKS = 64  # epochs of grid values gathered into snapshot rows at once
EPOCH_BATCH = 16  # lanes of the epoch scheduler (measured on the recording scene: 16 and 32 took 0.93× the CPU of 8)


@register
class _Epochs(Scheduler):
    """Epoch scheduler: all lanes advance together; snapshots from ``propagate_grid``."""

    name = "epochs"
    priority = 20
    batch_size = EPOCH_BATCH

    @classmethod
    def applies(cls, plan) -> bool:
        return bool(plan.snapshots)

    def __init__(self, scene, ta, layout, ics, traj_ids=None, **config):
        super().__init__(scene, ta, layout, ics, traj_ids, **config)
        self._handlers = None
        # the lane's orbit's last outward r_esc crossing (dissipative scenes, inlined rules): whether there is
        # one, its orbit time, its state (x, y, px, py of lane j at 4j..4j+3)
        self.has_out = np.zeros(self.B, dtype=np.uint8)
        self.out_t, self.out_state = np.zeros(self.B), np.zeros(4 * self.B)
        t_max = scene.t_max
        # P divides t_max, so censoring falls on an epoch's end
        self.n_epochs_max = max(1, math.ceil(t_max / EPOCH))
        self.P = t_max / self.n_epochs_max
        self.snaps = np.asarray(scene.snapshots or (), dtype=float)
        self.s_last = float(self.snaps[-1]) if self.snaps.size else -math.inf
        self.epoch = 0
        self.start_epoch = [0] * self.B
        self.zeros = np.zeros(self.B)

    def elapsed(self, lane):
        return ((self.epoch - self.start_epoch[lane]) * self.P + self.time_hi.item(lane)) + self.time_lo.item(lane)

    def release(self, lane):
        """Park the lane at the origin (a fixed point) until the epoch ends."""
        return self._parker()(lane)

    def _parker(self):
        """The lean :meth:`release` (a closure over the lanes' lists and flat memoryviews, no attribute lookup
        or method call per orbit end), built on first use and kept as the instance's ``release``."""
        orbit, pending_sec, pending_cross, commit_rows = (
            self.orbit,
            self.pending_sec,
            self.pending_cross,
            self.commit_rows,
        )
        s, B = self._s, self.B
        slots = tuple(i * B for i in range(self.layout.n_state))
        clock = self._clock_at if self.layout.clock is not None else None
        p, gate = self._p, self._gate_at
        if not (self.layout.gate is not None and self.gate_live):
            p = None

        def release(lane):
            if pending_sec[lane] or pending_cross[lane]:
                commit_rows(lane)
            orbit[lane] = -1
            for a in slots:
                s[a + lane] = 0.0
            if clock is not None:
                s[clock + lane] = 1.0
            if p is not None:
                p[gate + lane] = 0.0
            return True

        self.release = release
        return release

    @property
    def handlers(self):
        """{rule: callable (ta, direction, lane)}: the lean handlers of the escape, closure, far and r_esc rules
        (scenes without follow; the methods serve the section and clock rules), built on first use (a subclass
        sets its epoch length P after this class's construction)."""
        if self._handlers is None:
            self._handlers = self._inlined_handlers() if not self.follow else {}
        return self._handlers

    def _inlined_handlers(self):
        """The rules of :class:`hhscatter.integrate.lanes.LaneRules` for escape, closure, far and r_esc, written
        out with heyoka's callback signature: the lane's orbit time, state and the chunk's records read and
        written through flat memoryviews, the last outward r_esc crossing kept in per-lane arrays; no Python
        container per orbit end or per crossing (as the stream's, :mod:`hhscatter.integrate.stream`)."""
        B, P = self.B, self.P
        orbit, phase, start_epoch = self.orbit, self.phase, self.start_epoch
        s = memoryview(self.state.reshape(-1))  # s[i * B + lane]
        hi, lo = memoryview(self.time_hi), memoryview(self.time_lo)
        out, tend, timed = memoryview(self.outcome), memoryview(self.t_end), memoryview(self.lane_timed)
        end = memoryview(self.end_state.reshape(-1))  # end[4k + i]
        has, ot, ost = memoryview(self.has_out), memoryview(self.out_t), memoryview(self.out_state)
        b1, b2, b3 = B, 2 * B, 3 * B
        r_s2 = self.r_s * self.r_s
        cont, late, release = self.continue_settled, self.late, self._parker()
        escaped, settled, rerun, live, continuing = ESCAPED, SETTLED, RERUN, LIVE, CONTINUING
        lanes = self

        def now(lane):  # elapsed(lane)
            return ((lanes.epoch - start_epoch[lane]) * P + hi[lane]) + lo[lane]

        def here(lane, code):  # record(lane, code, elapsed(lane), state4(lane))
            k = orbit[lane]
            out[k] = code
            tend[k] = now(lane)
            timed[k] = 0
            j = 4 * k
            end[j] = s[lane]
            end[j + 1] = s[b1 + lane]
            end[j + 2] = s[b2 + lane]
            end[j + 3] = s[b3 + lane]

        def at_out(lane, code):  # record(lane, code, *last_out)
            k = orbit[lane]
            out[k] = code
            tend[k] = ot[lane]
            timed[k] = 0
            j, q = 4 * k, 4 * lane
            end[j] = ost[q]
            end[j + 1] = ost[q + 1]
            end[j + 2] = ost[q + 2]
            end[j + 3] = ost[q + 3]

        def on_escape(ta, d, lane):
            if orbit[lane] < 0 or phase[lane] != live:
                return True
            here(lane, escaped)
            return release(lane)

        def on_resc(ta, d, lane):
            if orbit[lane] >= 0 and phase[lane] == live:
                if d > 0:
                    has[lane] = 1
                    ot[lane] = now(lane)
                    q = 4 * lane
                    ost[q] = s[lane]
                    ost[q + 1] = s[b1 + lane]
                    ost[q + 2] = s[b2 + lane]
                    ost[q + 3] = s[b3 + lane]
                else:
                    has[lane] = 0
            return True

        def on_closure(ta, d, lane):
            if orbit[lane] < 0 or phase[lane] != live:
                return True
            x, y = s[lane], s[b1 + lane]
            if x * x + y * y <= r_s2:  # events.closure_rule, inlined
                here(lane, settled)
                if cont:
                    phase[lane] = continuing
                    return True
                return release(lane)
            if has[lane]:
                at_out(lane, escaped)
                return release(lane)
            return True

        def on_far(ta, d, lane):
            if orbit[lane] < 0:
                return True
            if phase[lane] == live:
                if not has[lane]:  # unreachable: r_far > r_esc; kept as a guard
                    raise RuntimeError("orbit reached r_far without crossing r_esc")
                if late is not None and late(now(lane), s[lane], s[b1 + lane], s[b2 + lane], s[b3 + lane]):
                    at_out(lane, rerun)
                else:
                    at_out(lane, escaped)
            return release(lane)  # (a followed orbit is gone)

        return {"escape": on_escape, "resc": on_resc, "closure": on_closure, "far": on_far}

    def close(self):
        super().close()
        self._handlers = {}  # the closures refer back to the lanes: free them now
        self.__dict__.pop("release", None)  # (the lean release holds views of the integrator)

    def _epoch_tables(self):
        """(grid, snap_times, has_snapshots) of :func:`epoch_tables` for this scene's P, epochs and snapshots."""
        return epoch_tables(self.P, self.n_epochs_max, tuple(self.snaps.tolist()))

    def run(self):
        B, ta, P, K, s_last = self.B, self.ta, self.P, self.n_epochs_max, self.s_last
        grid, snap_times, has_snapshots = self._epoch_tables()
        has = has_snapshots.tolist()
        orbit, phase, start_epoch, zeros = self.orbit, self.phase, self.start_epoch, self.zeros
        load, lanes = self._loader(), range(B)
        blocks, rows = [], []  # per propagate_grid call: (its values (n, dim, B), epoch index [B], orbit [B])
        n_returns = n_steps = 0
        for lane in lanes:
            load(lane)
        # each lane's orbit's epoch in the coming epoch (−1: a parked lane); whether a lane is live, has snapshots
        index, live, snap = [-1] * B, False, False
        for lane in lanes:
            if orbit[lane] >= 0:
                index[lane] = k = self.epoch - start_epoch[lane]
                live, snap = True, snap or has[k]
        while live:
            ta.set_time(zeros)
            if snap:
                ids = orbit[:]  # before the call: orbits end during it
                blocks.append((ta.propagate_grid(grid.take(index, axis=1))[1], index[:], ids))
                if len(blocks) >= SNAPSHOT_BLOCKS:
                    rows.append(self._snapshot_rows(blocks, snap_times))
                    blocks = []
            else:
                ta.propagate_until(P)
            n_returns += 1
            n_steps += self._checked()
            # close the epoch in one pass over the lanes: an orbit that needs nothing after it (t_max reached, or a
            # settled orbit continued past the last snapshot) is censored at t_max if still live and released; free
            # lanes are refilled in lane order and the next epoch's index is taken
            self.epoch = epoch = self.epoch + 1
            live = snap = False
            for lane in lanes:
                k = index[lane]
                if k >= 0 and orbit[lane] >= 0:
                    k += 1  # epochs completed
                    if k >= K or (phase[lane] == CONTINUING and k * P >= s_last):
                        if phase[lane] == LIVE:
                            self.record(lane, CENSORED, self.t_max, self.state4(lane))
                        self.release(lane)
                if orbit[lane] < 0:
                    load(lane)
                if orbit[lane] >= 0:
                    index[lane] = k = epoch - start_epoch[lane]
                    live = True
                    if has[k]:
                        snap = True
                else:
                    index[lane] = -1
        if blocks:
            rows.append(self._snapshot_rows(blocks, snap_times))
        ids = np.concatenate([r[0] for r in rows]) if rows else np.empty(0, np.int64)
        t = np.concatenate([r[1] for r in rows]) if rows else np.empty(0)
        e = np.concatenate([r[2] for r in rows]) if rows else np.empty(0)
        # rows after an orbit's end belong to no table (settled orbits continued: all rows)
        limit = np.where((self.outcome == SETTLED) & self.continue_settled, np.inf, self.t_end)
        keep = t <= limit[ids]
        return n_returns, n_steps, (ids[keep], t[keep], e[keep])

    def _checked(self) -> int:
        """After a propagation: the steps taken (when counted: heyoka's per-lane results read once), the
        integrator's state checked (a non-finite lane raises, naming it; one reduction: a non-finite value
        makes the sum non-finite)."""
        steps = 0
        if self.count_steps:
            for r in self.ta.propagate_res:
                steps += r[3]
        if not math.isfinite(self.state.sum()):
            _check(self.ta, self)
        return steps

    def _end_epoch(self, lanes, done) -> None:
        """Close the epoch: each lane of ``lanes`` whose orbit is done after it (``done(lane, k)``, k its epochs
        completed) is recorded as censored at t_max if still live, and released; the next epoch begins with the free
        lanes refilled."""
        epoch, start_epoch, phase = self.epoch, self.start_epoch, self.phase
        for lane in lanes:
            if done(lane, epoch - start_epoch[lane] + 1):
                if phase[lane] == LIVE:
                    self.record(lane, CENSORED, self.t_max, self.state4(lane))
                self.release(lane)
        self.epoch = epoch + 1
        for lane in range(self.B):
            if self.orbit[lane] < 0:
                self.load_next(lane)

    def _snapshot_rows(self, blocks, snap_times):
        """Energies at the snapshot grid points of buffered epochs, in bulk: (orbit, t, E) rows, in (epoch, grid
        point, lane) order; fillers and parked lanes are skipped by flat index, not copied."""
        out = np.stack([b[0] for b in blocks])  # (epochs, n, dim, B)
        epoch_index = np.array([b[1] for b in blocks], dtype=np.int64)  # (epochs, B)
        ids = np.array([b[2] for b in blocks], dtype=np.int64)
        _, n, dim, B = out.shape
        tt = snap_times[epoch_index].transpose(0, 2, 1)  # (epochs, n, B)
        e, j, b = np.nonzero(~np.isnan(tt) & (ids >= 0)[:, None, :])  # in (epoch, grid point, lane) order
        at = ((e * n + j) * dim) * B + b  # variable 0 of (epoch e, grid point j, lane b) in ``out``
        flat = out.reshape(-1)
        x, y, px, py = (flat[at + i * B] for i in range(4))
        return ids[e, b], tt[e, j, b], self.model.energy(x, y, px, py)

    def load_next(self, lane):
        k = self.next
        if k >= self.n:
            return
        self.next = k + 1
        self.start_epoch[lane] = self.epoch
        self.has_out[lane] = 0
        self.load_orbit(lane, k)

    def _loader(self):
        """:meth:`load_next` as one closure (the initial condition, the rule state of
        :meth:`hhscatter.integrate.lanes.LaneRules.start_orbit`, the gate and the clock written through flat
        memoryviews: no method call but heyoka's cooldown reset per orbit), or :meth:`load_next` itself where a
        subclass loads orbits its own way."""
        cls = type(self)
        if not (
            cls.load_next is _Epochs.load_next
            and cls.load_orbit is _BatchRules.load_orbit
            and cls.start_orbit is LaneRules.start_orbit
        ):
            return self.load_next
        B, n = self.B, self.n
        s, ic = self._s, self._ic
        b1, b2, b3 = B, 2 * B, 3 * B
        orbit, phase, last_out, sec_found, clock_i = self.orbit, self.phase, self.last_out, self.sec_found, self.clock_i
        pending_sec, pending_cross, start_epoch = self.pending_sec, self.pending_cross, self.start_epoch
        has = memoryview(self.has_out)
        load_tangent = self.load_tangent if self.tan0 is not None else None
        p, gate_at = (self._p, self._gate_at) if self.gate_live else (None, 0)
        gate0 = None if self.win is None or p is None else (1.0 if self.win.t_from <= 0 else 0.0)
        clock_at = self._clock_at
        sigma0 = self.targets[0][0] / self.clock_scale if self.targets else None
        open_late = self.open_late
        sigma_late = events.T_INITIAL / self.clock_scale if open_late is not None else None
        progress, reset, lanes = self.progress, self.ta.reset_cooldowns, self

        def load(lane):
            k = lanes.next
            if k >= n:
                return
            lanes.next = k + 1
            start_epoch[lane] = lanes.epoch
            has[lane] = 0
            if progress is not None:
                lanes.tick()
            j = 4 * k
            s[lane] = ic[j]
            s[b1 + lane] = ic[j + 1]
            s[b2 + lane] = ic[j + 2]
            s[b3 + lane] = ic[j + 3]
            if load_tangent is not None:
                load_tangent(lane, k)
            orbit[lane] = k
            phase[lane] = LIVE
            last_out[lane] = None
            sec_found[lane] = False
            clock_i[lane] = 0
            if pending_sec[lane]:
                pending_sec[lane] = []
            if pending_cross[lane]:
                pending_cross[lane] = []
            if gate0 is not None:
                p[gate_at + lane] = gate0
            if sigma0 is not None:
                s[clock_at + lane] = sigma0
            if open_late is not None and open_late[k]:  # the clock opens the window at T_INITIAL
                if p is not None:
                    p[gate_at + lane] = 0.0
                clock_i[lane] = -1
                s[clock_at + lane] = sigma_late
            reset(lane)

        return load


@functools.lru_cache(maxsize=8)
def epoch_tables(P: float, K: int, snapshots: tuple) -> tuple:
    """epoch_tables(P, K, snapshots) -> (grid, snap_times, has_snapshots): per epoch index k of an orbit (epochs of
    length P, K of them to t_max; ``snapshots`` the sorted snapshot times), its grid column and the orbit times of
    its snapshots. Built once per process and scene, not per chunk (~13 ms at K = 625; a chunk's plan is replaced
    per chunk when the no-return rule moves its far radius, which the tables do not depend on).

    Column k of ``grid`` (n, K + 1) holds the lane times of the snapshots s in [kP, (k+1)P) (the last epoch
    before t_max also (k+1)P), padded with fillers (strictly increasing, evaluated and discarded) to a common
    length n; row k of ``snap_times`` (K + 1, n) holds the snapshot times, NaN at fillers; index −1 (parked
    lanes) is all fillers. An epoch's grid is then one gather, ``grid[:, epoch_index]``, already in the (n, B)
    layout ``propagate_grid`` takes. The arrays are shared: read-only.

    Examples
    --------
    >>> grid, snap_times, has = epoch_tables(8.0, 2, (0.0, 4.0, 8.0, 9.0))
    >>> grid.T.tolist()  # lane times: epoch 0's snapshots 0, 4; epoch 1's 8, 9 at 0, 1; each epoch's end; parked
    [[0.0, 4.0, 8.0], [0.0, 1.0, 8.0], [0.0, 4.0, 8.0]]
    >>> snap_times.tolist()[:2], has.tolist()
    ([[0.0, 4.0, nan], [8.0, 9.0, nan]], [True, True, False])
    """
    S = np.asarray(snapshots, dtype=float)
    rows = []
    s_last = S[-1] if S.size else -math.inf
    for k in range(K):
        o = k * P
        # a snapshot on an epoch boundary belongs to the later epoch's start, except the last
        # snapshot (and t_max), which ends the earlier one: orbits that need nothing after
        # them stop there
        i0 = np.searchsorted(S, o, "right" if k and s_last <= o else "left")
        i1 = np.searchsorted(S, o + P, "right" if k + 1 == K or s_last <= o + P else "left")
        s = S[i0:i1]
        rows.append((s - o, s))
    m = max(int(((r[0] > 0) & (r[0] < P)).sum()) for r in rows)
    n = m + 2
    tau = np.empty((K + 1, n))
    tt = np.full((K + 1, n), np.nan)
    tau[:, 0], tau[:, -1] = 0.0, P
    for k, (t, s) in enumerate(rows + [(np.empty(0), np.empty(0))]):
        inner = (t > 0) & (t < P)
        j = int(inner.sum())
        tau[k, 1 : 1 + j] = t[inner]
        tt[k, 1 : 1 + j] = s[inner]
        a = t[inner][-1] if j else 0.0
        tau[k, 1 + j : -1] = a + (P - a) * np.arange(1, m - j + 1) / (m - j + 1)
        if len(t) and t[0] == 0.0:
            tt[k, 0] = s[0]
        if len(t) and t[-1] == P:
            tt[k, -1] = s[-1]
    out = np.ascontiguousarray(tau.T), tt, ~np.isnan(tt).all(axis=1)
    for a in out:
        a.flags.writeable = False
    return out
