"""Numba kernels of the peer integrators (imported lazily by :mod:`benchmarks.peers`).

This module imports numba at import time, so only :mod:`benchmarks.peers`
imports it, inside functions; the rest of the package never needs numba.

Units and model: Hénon–Heiles with ω = λ = 1 (paper, Eq. (eqn:hh_ham)) and
drag −γp, state (x, y, px, py).

Event kinds used by :func:`_rootfind` (value g and its time derivative ġ):

====  ======================  =====================================
kind  g                       ġ
====  ======================  =====================================
0     r² − c                  2 (x px + y py)
1     H − c                   −γ |p|²
2     x px + y py             |p|² + x fx + y fy   (section ṙ = 0)
====  ======================  =====================================

Outcome codes follow :mod:`hhscatter.integrate.engine`: 0 escaped, 1 settled,
2 censored; 3 = "section found" (section mode), −1 = inconsistent end (an
orbit reached r_far without a recorded outward r_esc crossing).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

ESCAPED, SETTLED, CENSORED, SECTION, BAD = 0, 1, 2, 3, -1
MODE_ESCAPE, MODE_DISSIPATIVE, MODE_SECTION = 0, 1, 2
T_INITIAL = 1e-10  # as the engine: a section crossing before this is the initial point


@njit(cache=True, inline="always")
def _force(x, y, px, py, gamma):
    return -x - 2.0 * x * y - gamma * px, -y - x * x + y * y - gamma * py


@njit(cache=True, inline="always")
def _energy(x, y, px, py):
    return 0.5 * (px * px + py * py) + 0.5 * (x * x + y * y) + x * x * y - y * y * y / 3.0


@njit(cache=True)
def _gval(kind, s, gamma, c):
    x, y, px, py = s[0], s[1], s[2], s[3]
    if kind == 0:
        return x * x + y * y - c, 2.0 * (x * px + y * py)
    if kind == 1:
        return _energy(x, y, px, py) - c, -gamma * (px * px + py * py)
    fx, fy = _force(x, y, px, py, gamma)
    return x * px + y * py, px * px + py * py + x * fx + y * fy


# -- KahanLi8: symmetric composition of 17 Störmer–Verlet (KDK) steps ----------


@njit(cache=True)
def kl8_step(s, h, a, b, out):
    """One KahanLi8 step of size h from s into out (kick b[i], drift a[i]; 17 force evaluations)."""
    x, y, px, py = s[0], s[1], s[2], s[3]
    fx, fy = _force(x, y, px, py, 0.0)
    for i in range(17):
        px += b[i] * h * fx
        py += b[i] * h * fy
        x += a[i] * h * px
        y += a[i] * h * py
        fx, fy = _force(x, y, px, py, 0.0)
    px += b[17] * h * fx
    py += b[17] * h * fy
    out[0], out[1], out[2], out[3] = x, y, px, py


@njit(cache=True)
def kl8_propagate(s0, h, nsteps, a, b):
    """State after ``nsteps`` KahanLi8 steps of size h (for the convergence test)."""
    s = s0.copy()
    w = np.empty(4)
    for _ in range(nsteps):
        kl8_step(s, h, a, b, w)
        s[:] = w
    return s


@njit(cache=True)
def _kl8_root(s0, t0, h, kind, c, a, b, g0, g1, out):
    """Safeguarded Newton for g(θ) = 0, θ ∈ (0, 1], state = KahanLi8 step of size θh from s0.

    Each trial re-integrates the partial step, so the event time has the
    method's own local accuracy (no interpolant). Returns the event time.
    """
    lo, hi, glo = 0.0, 1.0, g0
    th = g0 / (g0 - g1)  # secant start
    for _ in range(60):
        kl8_step(s0, th * h, a, b, out)
        g, dg = _gval(kind, out, 0.0, c)
        if g == 0.0:
            break
        if (g < 0.0) == (glo < 0.0):
            lo, glo = th, g
        else:
            hi = th
        new = th - g / (dg * h) if dg != 0.0 else 0.5 * (lo + hi)
        if not (lo < new < hi):
            new = 0.5 * (lo + hi)
        if abs(new - th) <= 2e-16 * max(th, 1e-300) or hi - lo <= 2e-16:
            th = new
            kl8_step(s0, th * h, a, b, out)
            break
        th = new
    return t0 + th * h


@njit(cache=True)
def kl8_run(ics, dt, r_esc, t_max, rootfind, mode, a, b):
    """KahanLi8 with fixed dt over orbits ``ics`` (n, 4), conservative.

    mode 0: escape when r > r_esc, checked at step ends (``rootfind`` False:
    t_end is the step end, as the authors did) or root-found inside the step.
    mode 2: stop at the first section crossing (ṙ = 0, φ̇ > 0), root-found.
    Returns (outcome, t_end, state_end, n_steps).
    """
    n = ics.shape[0]
    outcome = np.full(n, CENSORED, dtype=np.int8)
    t_end = np.full(n, t_max)
    s_end = np.empty((n, 4))
    n_steps = np.zeros(n, dtype=np.int64)
    kmax = int(math.ceil(t_max / dt - 1e-9))
    c = r_esc * r_esc
    s = np.empty(4)
    w = np.empty(4)
    r = np.empty(4)
    for i in range(n):
        s[:] = ics[i]
        g_old = s[0] * s[2] + s[1] * s[3]
        done = False
        for k in range(1, kmax + 1):
            kl8_step(s, dt, a, b, w)
            t0 = (k - 1) * dt
            if mode == MODE_ESCAPE:
                g1 = w[0] * w[0] + w[1] * w[1] - c
                if g1 > 0.0:
                    if rootfind:
                        g0 = s[0] * s[0] + s[1] * s[1] - c
                        t_end[i] = _kl8_root(s, t0, dt, 0, c, a, b, g0, g1, r)
                        s_end[i] = r
                    else:
                        t_end[i] = k * dt
                        s_end[i] = w
                    outcome[i] = ESCAPED
                    done = True
            else:
                g_new = w[0] * w[2] + w[1] * w[3]
                if (g_old < 0.0) != (g_new < 0.0) and g_new != 0.0:
                    tc = _kl8_root(s, t0, dt, 2, 0.0, a, b, g_old, g_new, r)
                    if tc > T_INITIAL and r[0] * r[3] - r[1] * r[2] > 0.0:
                        t_end[i] = tc
                        s_end[i] = r
                        outcome[i] = SECTION
                        done = True
                g_new2 = w[0] * w[0] + w[1] * w[1] - c
                if not done and g_new2 > 0.0:
                    t_end[i] = k * dt
                    s_end[i] = w
                    outcome[i] = ESCAPED
                    done = True
                g_old = g_new
            s[:] = w
            if done:
                n_steps[i] = k
                break
        if not done:
            s_end[i] = s
            n_steps[i] = kmax
    return outcome, t_end, s_end, n_steps


# -- DOP853 (Hairer's coefficients as shipped by SciPy), step control as SciPy --


@njit(cache=True)
def _rhs(s, gamma, out):
    out[0] = s[2]
    out[1] = s[3]
    fx, fy = _force(s[0], s[1], s[2], s[3], gamma)
    out[2] = fx
    out[3] = fy


@njit(cache=True)
def _dop_step(s, f0, h, gamma, A, B, C, K, tmp, out):
    """One DOP853 step of size h from s (f0 = f(s)); K[12] receives f(out) (FSAL)."""
    K[0, :] = f0
    for st in range(1, 12):
        for j in range(4):
            acc = 0.0
            for q in range(st):
                acc += A[st, q] * K[q, j]
            tmp[j] = s[j] + h * acc
        _rhs(tmp, gamma, K[st])
    for j in range(4):
        acc = 0.0
        for q in range(12):
            acc += B[q] * K[q, j]
        out[j] = s[j] + h * acc
    _rhs(out, gamma, K[12])


@njit(cache=True)
def _dop_err(s, snew, K, h, rtol, atol, E3, E5):
    e5 = 0.0
    e3 = 0.0
    for j in range(4):
        sc = atol + max(abs(s[j]), abs(snew[j])) * rtol
        a5 = 0.0
        a3 = 0.0
        for q in range(13):
            a5 += K[q, j] * E5[q]
            a3 += K[q, j] * E3[q]
        e5 += (a5 / sc) ** 2
        e3 += (a3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * 4.0)


@njit(cache=True)
def _dop_root(s0, f0, t0, h, kind, c, gamma, A, B, C, K, tmp, g0, g1, out):
    """Event time in a DOP853 step by safeguarded Newton on partial steps θh from s0."""
    lo, hi, glo = 0.0, 1.0, g0
    th = g0 / (g0 - g1)
    for _ in range(60):
        _dop_step(s0, f0, th * h, gamma, A, B, C, K, tmp, out)
        g, dg = _gval(kind, out, gamma, c)
        if g == 0.0:
            break
        if (g < 0.0) == (glo < 0.0):
            lo, glo = th, g
        else:
            hi = th
        new = th - g / (dg * h) if dg != 0.0 else 0.5 * (lo + hi)
        if not (lo < new < hi):
            new = 0.5 * (lo + hi)
        if abs(new - th) <= 2e-16 * max(th, 1e-300) or hi - lo <= 2e-16:
            th = new
            _dop_step(s0, f0, th * h, gamma, A, B, C, K, tmp, out)
            break
        th = new
    return t0 + th * h


@njit(cache=True)
def _initial_step(s, f, gamma, rtol, atol, tmp, f1):
    d0 = 0.0
    d1 = 0.0
    for j in range(4):
        sc = atol + abs(s[j]) * rtol
        d0 += (s[j] / sc) ** 2
        d1 += (f[j] / sc) ** 2
    d0 = math.sqrt(d0 / 4.0)
    d1 = math.sqrt(d1 / 4.0)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    for j in range(4):
        tmp[j] = s[j] + h0 * f[j]
    _rhs(tmp, gamma, f1)
    d2 = 0.0
    for j in range(4):
        sc = atol + abs(s[j]) * rtol
        d2 += ((f1[j] - f[j]) / sc) ** 2
    d2 = math.sqrt(d2 / 4.0) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1)


@njit(cache=True)
def dop853_run(ics, gamma, rtol, atol, r_esc, r_far, e_c, r_s, t_max, mode, A, B, C, E3, E5):
    """Adaptive DOP853 over orbits ``ics`` (n, 4) with the engine's escape rules.

    Events are detected by a sign change of g between accepted step ends (as
    SciPy and DifferentialEquations.jl do) and located by Newton on partial
    steps. mode 0: conservative escape (r² − r_esc² upward, terminal).
    mode 1: dissipative (closure H = E_c downward: settled if r ≤ r_s, else
    escaped at the last outward r_esc crossing; r > r_far: escaped likewise).
    mode 2: conservative, stop at the first section crossing with φ̇ > 0.
    Returns (outcome, t_end, state_end, n_steps, n_fev).
    """
    n = ics.shape[0]
    outcome = np.full(n, CENSORED, dtype=np.int8)
    t_end = np.full(n, t_max)
    s_end = np.empty((n, 4))
    n_steps = np.zeros(n, dtype=np.int64)
    n_fev = np.zeros(n, dtype=np.int64)
    K = np.empty((13, 4))
    tmp = np.empty(4)
    s = np.empty(4)
    f = np.empty(4)
    w = np.empty(4)
    r = np.empty(4)
    lo_s = np.empty(4)
    lo_f = np.empty(4)
    fw = np.empty(4)
    ce = r_esc * r_esc
    cf = r_far * r_far
    for i in range(n):
        s[:] = ics[i]
        _rhs(s, gamma, f)
        h = _initial_step(s, f, gamma, rtol, atol, tmp, w)
        nf = 2
        t = 0.0
        rejected = False
        have_out = False
        lo_t = 0.0
        lo_h = 0.0
        done = False
        steps = 0
        while not done:
            if t >= t_max:
                s_end[i] = s
                break
            h = min(h, t_max - t)
            # one accepted step
            while True:
                _dop_step(s, f, h, gamma, A, B, C, K, tmp, w)
                nf += 12
                en = _dop_err(s, w, K, h, rtol, atol, E3, E5)
                if en < 1.0:
                    if en == 0.0:
                        fac = 10.0
                    else:
                        fac = min(10.0, 0.9 * en ** (-1.0 / 8.0))
                    if rejected:
                        fac = min(1.0, fac)
                    rejected = False
                    break
                h *= max(0.2, 0.9 * en ** (-1.0 / 8.0))
                rejected = True
            fw[:] = K[12]  # f at the step end (FSAL); K is reused by root finding
            steps += 1
            t_new = t + h if h < t_max - t else t_max
            g_r0 = s[0] * s[0] + s[1] * s[1] - ce
            g_r1 = w[0] * w[0] + w[1] * w[1] - ce
            if mode == MODE_DISSIPATIVE:
                if (g_r0 < 0.0) != (g_r1 < 0.0):
                    if g_r1 > 0.0:
                        have_out = True
                        lo_t = t
                        lo_h = h
                        lo_s[:] = s
                        lo_f[:] = f
                    else:
                        have_out = False
                e0 = _energy(s[0], s[1], s[2], s[3]) - e_c
                e1 = _energy(w[0], w[1], w[2], w[3]) - e_c
                if e0 >= 0.0 and e1 < 0.0:
                    tc = _dop_root(s, f, t, h, 1, e_c, gamma, A, B, C, K, tmp, e0, e1, r)
                    if r[0] * r[0] + r[1] * r[1] <= r_s * r_s:
                        outcome[i] = SETTLED
                        t_end[i] = tc
                        s_end[i] = r
                        done = True
                    elif have_out:
                        done = True
                if not done and w[0] * w[0] + w[1] * w[1] > cf:
                    if have_out:
                        done = True
                    else:
                        outcome[i] = BAD
                        t_end[i] = t_new
                        s_end[i] = w
                        done = True
                        break
                if done and outcome[i] != SETTLED:
                    gs0 = lo_s[0] * lo_s[0] + lo_s[1] * lo_s[1] - ce
                    _dop_step(lo_s, lo_f, lo_h, gamma, A, B, C, K, tmp, r)
                    gs1 = r[0] * r[0] + r[1] * r[1] - ce
                    t_end[i] = _dop_root(lo_s, lo_f, lo_t, lo_h, 0, ce, gamma, A, B, C, K, tmp, gs0, gs1, r)
                    s_end[i] = r
                    outcome[i] = ESCAPED
            elif mode == MODE_ESCAPE:
                if g_r0 < 0.0 and g_r1 >= 0.0:
                    t_end[i] = _dop_root(s, f, t, h, 0, ce, gamma, A, B, C, K, tmp, g_r0, g_r1, r)
                    s_end[i] = r
                    outcome[i] = ESCAPED
                    done = True
            else:
                g0 = s[0] * s[2] + s[1] * s[3]
                g1 = w[0] * w[2] + w[1] * w[3]
                if (g0 < 0.0) != (g1 < 0.0) and g1 != 0.0:
                    tc = _dop_root(s, f, t, h, 2, 0.0, gamma, A, B, C, K, tmp, g0, g1, r)
                    if tc > T_INITIAL and r[0] * r[3] - r[1] * r[2] > 0.0:
                        t_end[i] = tc
                        s_end[i] = r
                        outcome[i] = SECTION
                        done = True
                if not done and g_r1 >= 0.0:
                    t_end[i] = t_new
                    s_end[i] = w
                    outcome[i] = ESCAPED
                    done = True
            s[:] = w
            f[:] = fw
            t = t_new
            h *= fac
        n_steps[i] = steps
        n_fev[i] = nf
    return outcome, t_end, s_end, n_steps, n_fev


# -- BAOAB: Langevin dynamics by B(h/2) A(h/2) O(h) A(h/2) B(h/2) ---------------


@njit(cache=True)
def baoab_run(ics, gamma, temperature, dt, r_esc, t_max, seed):
    """Escape times of Langevin orbits (drag γ, heat bath T) by BAOAB (Leimkuhler & Matthews 2013), one orbit
    after the other; an orbit escapes at the end of the first step with r > r_esc (resolved to dt). numba's
    own generator, seeded once: (t_end, escaped)."""
    np.random.seed(seed)
    n = ics.shape[0]
    c = math.exp(-gamma * dt)
    s = math.sqrt(temperature * (1.0 - c * c))
    steps = int(round(t_max / dt))
    r2 = r_esc * r_esc
    t_end = np.full(n, t_max)
    escaped = np.zeros(n, dtype=np.bool_)
    hh = 0.5 * dt
    for i in range(n):
        x, y, px, py = ics[i, 0], ics[i, 1], ics[i, 2], ics[i, 3]
        fx, fy = _force(x, y, px, py, 0.0)
        for k in range(1, steps + 1):
            px += hh * fx
            py += hh * fy
            x += hh * px
            y += hh * py
            px = c * px + s * np.random.standard_normal()
            py = c * py + s * np.random.standard_normal()
            x += hh * px
            y += hh * py
            fx, fy = _force(x, y, px, py, 0.0)
            px += hh * fx
            py += hh * fy
            if x * x + y * y > r2:
                t_end[i] = k * dt
                escaped[i] = True
                break
    return t_end, escaped
