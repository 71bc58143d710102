"""Peer integrators for the work–precision benchmark (``make bench``).

All peers integrate the same Hénon–Heiles system (ω = λ = 1, paper
Eq. (eqn:hh_ham), drag −γp) from the same initial conditions with the
engine's escape rules (:mod:`hhscatter.integrate.engine`), and return the same arrays:
``PeerResult(outcome, t_end, state_end, n_steps)``.

* :func:`kahanli8` — the paper's conservative integrator (App. "Integrators":
  "8th-order symplectic integrator [Kahan & Li 1997] with timestep dt = 0.01"),
  compiled with numba. Scheme: **KahanLi8 as in OrdinaryDiffEq.jl**
  (``KahanLi8ConstantCache`` in ``src/tableaus/symplectic_tableaus.jl``,
  SciML/OrdinaryDiffEq.jl): the symmetric composition of 17 Störmer–Verlet
  steps with the 9 distinct weights :data:`KAHANLI8_GAMMA`
  (Kahan & Li, Math. Comp. 66 (1997) 1089, scheme "s17odr8a"); in
  OrdinaryDiffEq's kick/drift form the drift coefficients are
  a = (γ1…γ9…γ1, 0) and the kicks b_i = (a_{i−1} + a_i)/2. Not the 15-stage
  "s15odr8" set. Order 8 is checked numerically in tests/bench/test_bench_peers.py.
  Escape is checked at step ends (``rootfind=False``: t_end = the first step end
  with r > r_esc, as the authors' fixed-step runs) or root-found inside that
  step by Newton on re-integrated partial steps (``rootfind=True``).
* :func:`dop853` — adaptive DOP853 (Hairer's 8(5,3) pair; coefficients taken
  from SciPy's ``scipy.integrate._ivp.dop853_coefficients``, step control as
  SciPy's), compiled with numba, events by sign change between step ends and
  Newton on partial steps. The paper used Vern9 in Julia for the dissipative
  runs; DOP853 is the compiled adaptive high-order Runge–Kutta method of the comparison.
* :func:`scipy_dop853` — ``scipy.integrate.solve_ivp(method="DOP853")`` with
  terminal events (pure Python overhead; run on a subset).
* :func:`engine` — hhscatter's batch Taylor engine (:func:`hhscatter.integrate.engine.run_chunk`).

numba is a benchmark-only dependency (extra ``bench``); it is imported on
first use only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hhscatter.integrate.engine import run_chunk
from hhscatter.model import HenonHeiles

# Kahan & Li (1997) s17odr8a weights, as in OrdinaryDiffEq.jl's KahanLi8ConstantCache
# (γ1..γ8, then the middle weight γ9; the composition is γ1..γ8, γ9, γ8..γ1).
KAHANLI8_GAMMA = (
    0.13020248308889008087881763,
    0.56116298177510838456196441,
    -0.38947496264484728640807860,
    0.15884190655515560089621075,
    -0.39590389413323757733623154,
    0.18453964097831570709183254,
    0.25837438768632204729397911,
    0.29501172360931029887096624,
    -0.60550853383003451169892108,
)

E_C = HenonHeiles().critical_energy  # E_c of the model (ω = λ = 1: 1/6)
R_SADDLE = 1.0


@dataclass
class PeerResult:
    """Per-orbit arrays: outcome (int8, engine codes; 3 = section found), t_end, state_end (n, 4), n_steps."""

    outcome: np.ndarray
    t_end: np.ndarray
    state_end: np.ndarray | None
    n_steps: np.ndarray
    e_end: np.ndarray | None = None  # energy at t_end (filled from state_end when None)

    def __post_init__(self):
        if self.e_end is None and self.state_end is not None:
            x, y, px, py = self.state_end.T
            self.e_end = 0.5 * (px * px + py * py) + 0.5 * (x * x + y * y) + x * x * y - y**3 / 3.0


def kahanli8_coefficients():
    """kahanli8_coefficients() -> (a, b): drift and kick coefficients, arrays of length 18.

    a = (γ1, …, γ8, γ9, γ8, …, γ1, 0), b_1 = a_1/2, b_i = (a_{i−1} + a_i)/2, b_18 = a_17/2
    (OrdinaryDiffEq.jl's layout). Σa = Σb = 1.
    """
    g = np.array(KAHANLI8_GAMMA)
    a = np.concatenate([g, g[7::-1], [0.0]])
    b = np.empty(18)
    b[0] = a[0] / 2
    b[1:] = (a[:-1] + a[1:]) / 2
    return a, b


def _kernels():
    try:
        from benchmarks import _kernels as k  # deferred: numba compiles the kernels on import (optional [bench] extra)
    except ImportError as exc:  # numba missing
        raise ImportError("the benchmark peers need numba: pip install -e '.[bench]' (or `make bench`)") from exc
    return k


def _check_ics(ics):
    ics = np.ascontiguousarray(ics, dtype=float)
    if ics.ndim != 2 or ics.shape[1] != 4:
        raise ValueError(f"ics must have shape (n, 4), got {ics.shape}")
    return ics


def kahanli8(ics, dt, *, r_esc=1.03, t_max=5000.0, rootfind=False, section=False) -> PeerResult:
    """kahanli8(ics, dt, r_esc=1.03, t_max=5000, rootfind=False, section=False) -> PeerResult.

    Conservative only. ``section=True``: stop at the first crossing of the
    section ṙ = 0 with φ̇ > 0 (outcome 3, root-found), or at escape/t_max.
    """
    if not dt > 0:
        raise ValueError(f"dt must be > 0, got {dt!r}")
    k = _kernels()
    a, b = kahanli8_coefficients()
    mode = k.MODE_SECTION if section else k.MODE_ESCAPE
    o, t, s, n = k.kl8_run(_check_ics(ics), float(dt), float(r_esc), float(t_max), bool(rootfind), mode, a, b)
    return PeerResult(o, t, s, n)


def kahanli8_propagate(state, dt, nsteps):
    """kahanli8_propagate(state, dt, nsteps) -> state after nsteps KahanLi8 steps (convergence tests)."""
    a, b = kahanli8_coefficients()
    return _kernels().kl8_propagate(np.asarray(state, dtype=float), float(dt), int(nsteps), a, b)


def _dop_tables():
    from scipy.integrate._ivp import dop853_coefficients as d  # deferred: scipy loads on first use

    A = np.ascontiguousarray(d.A[:12, :12])
    return (
        A,
        np.ascontiguousarray(d.B),
        np.ascontiguousarray(d.C[:12]),
        np.ascontiguousarray(d.E3),
        np.ascontiguousarray(d.E5),
    )


def dop853(ics, tol, *, gamma=0.0, r_esc=1.03, r_far=10.0, t_max=5000.0, section=False) -> PeerResult:
    """dop853(ics, tol, gamma=0, r_esc=1.03, r_far=10, t_max=5000, section=False) -> PeerResult.

    rtol = atol = tol. γ > 0 selects the dissipative rules (closure at E_c,
    escape time = last outward r_esc crossing, stop at r_far).
    """
    if not 0 < tol < 1:
        raise ValueError(f"tol must be in (0, 1), got {tol!r}")
    if gamma < 0:
        raise ValueError(f"gamma must be ≥ 0, got {gamma!r}")
    k = _kernels()
    mode = k.MODE_SECTION if section else (k.MODE_DISSIPATIVE if gamma > 0 else k.MODE_ESCAPE)
    A, B, C, E3, E5 = _dop_tables()
    o, t, s, n, _ = k.dop853_run(
        _check_ics(ics),
        float(gamma),
        float(tol),
        float(tol),
        float(r_esc),
        float(r_far),
        E_C,
        R_SADDLE,
        float(t_max),
        mode,
        A,
        B,
        C,
        E3,
        E5,
    )
    return PeerResult(o, t, s, n)


def _rhs_py(gamma):
    def f(t, s):
        x, y, px, py = s
        return [px, py, -x - 2.0 * x * y - gamma * px, -y - x * x + y * y - gamma * py]

    return f


def scipy_dop853(ics, tol, *, gamma=0.0, r_esc=1.03, r_far=10.0, t_max=5000.0) -> PeerResult:
    """scipy_dop853(ics, tol, gamma=0, ...) -> PeerResult via ``solve_ivp(method="DOP853")``.

    Conservative: terminal event r² − r_esc² (upward). Dissipative: terminal
    closure event H − E_c (downward; settled if r ≤ r_s) and r² − r_far²;
    the escape time is the last outward r_esc crossing (non-terminal event).
    rtol = atol = tol. Orbits that the closure leaves outside Ω are continued
    to r_far as in the engine.
    """
    from scipy.integrate import solve_ivp  # deferred: scipy loads on first use

    ics = _check_ics(ics)
    n = len(ics)
    out = PeerResult(np.full(n, 2, np.int8), np.full(n, t_max), None, np.zeros(n, np.int64))
    out.state_end = np.empty((n, 4))
    f = _rhs_py(gamma)

    def ev_esc(t, s):
        return s[0] * s[0] + s[1] * s[1] - r_esc * r_esc

    def ev_close(t, s):
        x, y, px, py = s
        return 0.5 * (px * px + py * py) + 0.5 * (x * x + y * y) + x * x * y - y**3 / 3.0 - E_C

    def ev_far(t, s):
        return s[0] * s[0] + s[1] * s[1] - r_far * r_far

    for i, ic in enumerate(ics):
        if gamma == 0:
            ev_esc.terminal, ev_esc.direction = True, 1
            sol = solve_ivp(f, (0.0, t_max), ic, method="DOP853", rtol=tol, atol=tol, events=[ev_esc])
            out.n_steps[i] = sol.t.size - 1
            if sol.status == 1:
                out.outcome[i], out.t_end[i], out.state_end[i] = 0, sol.t_events[0][0], sol.y_events[0][0]
            else:
                out.state_end[i] = sol.y[:, -1]
            continue
        ev_esc.terminal, ev_esc.direction = False, 0
        ev_close.terminal, ev_close.direction = True, -1
        ev_far.terminal, ev_far.direction = True, 1
        t0, s0, steps, last_out = 0.0, ic, 0, None
        while True:
            sol = solve_ivp(f, (t0, t_max), s0, method="DOP853", rtol=tol, atol=tol, events=[ev_esc, ev_close, ev_far])
            steps += sol.t.size - 1
            for te, ye in zip(sol.t_events[0], sol.y_events[0]):
                last_out = (te, ye) if ye[0] * ye[2] + ye[1] * ye[3] > 0 else None
            if sol.status != 1:
                out.state_end[i] = sol.y[:, -1]
                break
            if sol.t_events[1].size:
                ye = sol.y_events[1][0]
                if ye[0] ** 2 + ye[1] ** 2 <= R_SADDLE**2:
                    out.outcome[i], out.t_end[i], out.state_end[i] = 1, sol.t_events[1][0], ye
                    break
                if last_out is None:  # outside Ω below E_c: continue to r_far
                    t0, s0 = sol.t_events[1][0], ye
                    ev_close.terminal = False
                    continue
            if last_out is None:
                out.outcome[i], out.t_end[i], out.state_end[i] = -1, sol.t[-1], sol.y[:, -1]
                break
            out.outcome[i], out.t_end[i], out.state_end[i] = 0, last_out[0], last_out[1]
            break
        ev_close.terminal = True
        out.n_steps[i] = steps
    return PeerResult(out.outcome, out.t_end, out.state_end, out.n_steps)


def engine(ics, tol, *, gamma=0.0, energy=None, r_esc=1.03, t_max=5000.0, batch_size=4, section=False) -> PeerResult:
    """engine(ics, tol, gamma=0, energy=None, ..., batch_size=4, section=False) -> PeerResult.

    hhscatter's engine (:func:`hhscatter.integrate.engine.run_chunk`) on these ICs in one
    process. ``section=True`` records the first section crossing (window
    ``first_only``); its outcome is then 3 where a crossing was found and the
    state/time are the crossing's.
    """
    from hhscatter.scene.scene import (  # deferred: pydantic loads on first use
        Scene,
        SectionWindow,
    )

    ics = _check_ics(ics)
    if energy is None:
        energy = float(HenonHeiles().energy(*ics[0]))
    sc = Scene(
        energy=energy,
        n=len(ics),
        gamma=gamma,
        tol=tol,
        r_esc=r_esc,
        t_max=t_max,
        batch_size=batch_size,
        sections=SectionWindow(first_only=True) if section else None,
    )
    res = run_chunk(sc, ics, np.arange(len(ics)), batch_size=batch_size)
    lt = res.lifetimes
    st = np.full((len(ics), 4), np.nan)
    if not section:
        # run_chunk reports the end energy, not the end state
        return PeerResult(
            lt["outcome"].copy(), lt["t_end"].copy(), None, np.zeros(len(ics), np.int64), e_end=lt["e_end"].copy()
        )
    out = PeerResult(lt["outcome"].copy(), lt["t_end"].copy(), st, np.zeros(len(ics), np.int64))
    sec = res.sections
    idx = sec["traj_id"]
    out.outcome[idx] = 3
    out.t_end[idx] = sec["t"]
    out.state_end[idx] = np.column_stack([sec["x"], sec["y"], sec["px"], sec["py"]])
    return out


__all__ = [
    "KAHANLI8_GAMMA",
    "PeerResult",
    "dop853",
    "engine",
    "kahanli8",
    "kahanli8_coefficients",
    "kahanli8_propagate",
    "scipy_dop853",
]


def baoab(ics, dt, *, gamma, temperature, r_esc=1.5, t_max=150.0, seed=1):
    """Langevin escape times of Hénon–Heiles by a compiled BAOAB at step ``dt`` (time units): drag γ (1/time),
    heat bath T (energy units); escapes resolved to ``dt``. Returns (t_end, escaped) arrays."""
    k = _kernels()
    return k.baoab_run(
        _check_ics(ics), float(gamma), float(temperature), float(dt), float(r_esc), float(t_max), int(seed)
    )
