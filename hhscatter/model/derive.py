"""What a declared potential implies: critical points, exits, E_c, Ω and the no-return radius R(E).

Given V(x, y) as a sympy expression in x and y (parameters substituted, :func:`hhscatter.model.parse.substitute`),
:func:`derive` finds

1. **the critical points** ∇V = 0: for a polynomial V symbolically (a lex Gröbner basis of (V_x, V_y): if it
   is not zero-dimensional the critical points form curves and nothing can be derived; otherwise the real
   roots of its two eliminants give every critical point, polished by Newton's method); for any other V
   (a polynomial with irrational coefficients such as pi included)
   numerically (damped Newton from a polar grid of starts out to :data:`SEARCH_RADIUS`, deduplicated);
2. **their kind** from the Hessian's eigenvalues: ``minimum``, ``saddle``, ``maximum`` or ``degenerate``
   (an eigenvalue below 1e-8 of the largest; lines of critical points and monkey saddles are degenerate);
3. **the well**: V's minimum must sit at the origin with V(0, 0) = 0, or a :class:`ConfigError` says where it is;
4. **the exits**: from each saddle the two steepest-descent paths (ẋ = −∇V/(1 + |∇V|), started along the
   Hessian's descending eigenvector) end at a minimum or beyond the no-return radius R(E_s) of the saddle's
   energy, past which r grows without bound along the path (the radial force is outward wherever V ≤ E_s).
   Joining minima and infinite ends by their saddles in order of energy (union–find), a saddle is an exit
   when one side lies in the well's basin below its energy and the other in a basin that reaches infinity
   (and not the well's): orbits from the well pass it and can reach infinity. Exits opening at different
   energies are all kept, each with its own energy; E_c is the lowest;
5. **Ω**: the disk r ≤ the largest distance of the exits opening at E_c, checked on a grid to contain the
   well's part of {V < E_c} and to meet no other part;
6. **R(E)** (:func:`~hhscatter.model.landscape.no_return_radius`): the smallest R beyond which −∂V/∂r > 0 at every point with V ≤ E,
   from a polar grid refined by constrained optimisation (for Hénon–Heiles it reproduces √(6E)/ω).

Steps 1–3 and 6 (V as numbers, the critical points, the well, R(E)) are :mod:`hhscatter.model.landscape`.
Every step that cannot decide raises a :class:`~hhscatter.errors.ConfigError` naming the ``[system]`` key
that overrides it (``critical_energy``, ``exits``, ``omega_radius``). A value given for one of them is checked
against the derivation wherever it can decide (a contradiction is refused, naming both values), and for
consistency where it cannot: given exits are critical points of V at their stated energy, E_c is the lowest exit's
energy, Ω holds the well's part of {V < E_c} and meets no other part.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hhscatter.errors import ConfigError
from hhscatter.model.base import Exit
from hhscatter.model.landscape import (  # noqa: F401 - the landscape's public names are importable from here too
    DEGENERATE,
    NO_RETURN_MARGIN,
    SEARCH_RADIUS,
    CriticalPoint,
    Landscape,
    check_well,
    critical_points,
    no_return_radius,
)

#: steps after which a steepest-descent path that has neither reached a minimum nor R(E) is given up
MAX_DESCENT_STEPS = 20_000
#: relative tolerance of a given override against what it is checked with (∇V = 0 at a given exit, its energy V
#: there, a given E_c against the lowest exit's energy, a given exit against a derived one)
GIVEN_TOL = 1e-8


@dataclass(frozen=True)
class Derivation:
    """What :func:`derive` found.

    Parameters
    ----------
    critical_points : tuple of CriticalPoint
        Every critical point found (empty when exits were given).
    exits : tuple of Exit
        The exits in channel order (ascending polar angle in [0, 2π)).
    critical_energy : float
        E_c (energy).
    omega_radius : float
        Ω's radius (length).
    method : str
        How the critical points were found: ``"symbolic"``, ``"numeric"`` or ``"given"`` (exits given).
    seconds : float
        Wall time of the derivation (s).

    Examples
    --------
    >>> from hhscatter.model.parse import parse_potential
    >>> d = derive(parse_potential("x**2/2 + y**2/2 + x**2*y - y**3/3"))
    >>> round(d.critical_energy, 15), len(d.exits), d.method
    (0.166666666666667, 3, 'symbolic')
    """

    critical_points: tuple[CriticalPoint, ...]
    exits: tuple[Exit, ...]
    critical_energy: float
    omega_radius: float
    method: str
    seconds: float = field(compare=False)


def _descend(
    land: Landscape, x0: float, y0: float, r_out: float, minima: Sequence[CriticalPoint]
) -> tuple[float, float, bool]:
    """Follow ẋ = −∇V/(1 + |∇V|) from (x0, y0): (end x, end y, True if it passed r_out).

    Stops beyond r_out, within 1e-6 (1 + |m|) of a known minimum m, where |∇V| falls below 1e-10, at t = 1e5 or
    after :data:`MAX_DESCENT_STEPS` steps.
    """
    from scipy.integrate import solve_ivp  # deferred: scipy.integrate loads on first use

    grad = land.scalar_gradient
    mins = [(m.x, m.y, 1e-6 * (1 + m.distance)) for m in minima]

    def rhs(_, z):
        try:
            gx, gy = grad(z[0], z[1])
            n = 1.0 + math.hypot(gx, gy)
            out = [-gx / n, -gy / n]
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):  # math.sqrt(-1), log(0), a complex value
            raise _NotFinite(z) from None
        if not (math.isfinite(out[0]) and math.isfinite(out[1])):
            raise _NotFinite(z)
        return out

    def out(_, z):
        return math.hypot(z[0], z[1]) - r_out

    def near(_, z):
        return min(math.hypot(z[0] - mx, z[1] - my) - tol for mx, my, tol in mins)

    def still(_, z):
        return math.hypot(*grad(z[0], z[1])) - 1e-10

    for ev in (out, near, still):
        ev.terminal = True
    near.direction = still.direction = -1
    calls = [0]

    def counted(t, z):  # gives up a path that crawls (e.g. up a narrowing channel)
        calls[0] += 1
        if calls[0] > 6 * MAX_DESCENT_STEPS:  # RK45: 6 evaluations per step
            raise _GiveUp(z)
        return rhs(t, z)

    try:
        sol = solve_ivp(counted, (0.0, 1e5), [x0, y0], events=[out, near, still], rtol=1e-8, atol=1e-11)
    except _GiveUp as e:
        return float(e.args[0][0]), float(e.args[0][1]), False
    except _NotFinite as e:
        raise ConfigError(
            f"the potential or its gradient is not finite at ({e.args[0][0]:.6g}, {e.args[0][1]:.6g}) "
            f"on the steepest descent from the saddle near ({x0:.6g}, {y0:.6g}): give a potential that "
            "is finite and real in the plane around the well and its exits"
        ) from None
    xe, ye = sol.y[:, -1]
    return float(xe), float(ye), bool(sol.t_events[0].size)


class _GiveUp(Exception):
    """A steepest-descent path took more than MAX_DESCENT_STEPS steps."""


class _NotFinite(Exception):
    """A steepest-descent path reached a point where V or its gradient is not finite (or not real)."""


class _Union:
    def __init__(self):
        self.parent: dict[Any, Any] = {}

    def find(self, a):
        self.parent.setdefault(a, a)
        while self.parent[a] != a:
            self.parent[a] = self.parent[self.parent[a]]
            a = self.parent[a]
        return a

    def union(self, a, b):
        self.parent[self.find(a)] = self.find(b)


def find_exits(land: Landscape, points: Sequence[CriticalPoint], scale: float) -> tuple[Exit, ...]:
    """The saddles through which orbits from the well reach infinity (module docstring, step 4)."""
    minima = [p for p in points if p.kind == "minimum"]
    well = next(i for i, p in enumerate(minima) if p.distance == 0.0)
    saddles = [p for p in points if p.kind == "saddle"]
    ends = []
    r_nr: dict[float, float] = {}
    for k, s in enumerate(saddles):
        a, b, c = (float(h) for h in land.hessian(s.x, s.y))
        w, v = np.linalg.eigh(np.array([[a, b], [b, c]]))
        # the descending eigenvector, turned by 1e-6 rad: a path started exactly on a symmetry axis could
        # otherwise run into another saddle along its stable manifold
        c, sn = math.cos(1e-6), math.sin(1e-6)
        d = np.array([c * v[0, 0] - sn * v[1, 0], sn * v[0, 0] + c * v[1, 0]])
        h = 1e-5 * s.distance
        if s.energy not in r_nr:
            value = no_return_radius(land, s.energy, scale)
            r_nr.update(
                {p.energy: value for p in saddles if abs(p.energy - s.energy) <= 1e-12 * max(1.0, abs(s.energy))}
            )
        r_out = max(r_nr[s.energy], 1.5 * s.distance)
        pair = []
        for sign in (1, -1):
            xe, ye, escaped = _descend(land, s.x + sign * h * d[0], s.y + sign * h * d[1], r_out, minima)
            if escaped:
                pair.append(("inf", k, sign))
                continue
            hit = [i for i, m in enumerate(minima) if math.hypot(xe - m.x, ye - m.y) < 1e-4 * (1 + m.distance)]
            if not hit:
                raise ConfigError(
                    f"the steepest descent from the saddle at ({s.x:.6g}, {s.y:.6g}) (V = "
                    f"{s.energy:.6g}) ends at ({xe:.6g}, {ye:.6g}), neither a minimum nor infinity: "
                    "cannot tell whether orbits leave through it; give `critical_energy` and "
                    "`exits` in [system]"
                )
            pair.append(("min", hit[0]))
        ends.append(pair)
    uf = _Union()
    has_inf: dict[Any, bool] = {}

    def infinite(node) -> bool:
        root = uf.find(node)
        return any(uf.find(n) == root for n in has_inf)

    for e in ends:
        for node in e:
            if node[0] == "inf":
                has_inf[node] = True
    W = ("min", well)
    exits = []
    order = sorted(range(len(saddles)), key=lambda k: saddles[k].energy)
    i = 0
    while i < len(order):  # saddles of (numerically) equal energy are judged against the same basins
        j = i
        e0 = saddles[order[i]].energy
        while j < len(order) and saddles[order[j]].energy <= e0 + 1e-12 * max(1.0, abs(e0)):
            j += 1
        group = order[i:j]
        for k in group:
            a, b = ends[k]
            for p, q in ((a, b), (b, a)):
                if uf.find(p) == uf.find(W) and uf.find(q) != uf.find(W) and infinite(q):
                    exits.append(saddles[k])
                    break
        for k in group:
            uf.union(*ends[k])
        i = j
    return tuple(Exit(s.x, s.y, s.energy) for s in _channel_order(exits))


def _channel_order(exits):
    """Exits by ascending polar angle in [0, 2π) (then distance): channel k is exits[k]."""

    def angle(e):
        a = math.atan2(e.y, e.x) % (2 * math.pi)
        return 0.0 if a > 2 * math.pi - 1e-12 else a

    return sorted(exits, key=lambda e: (round(angle(e), 12), math.hypot(e.x, e.y)))


# -- Ω ---------------------------------------------------------------------------------------------------
def check_omega(
    land: Landscape, radius: float, critical_energy: float, exits: Sequence[Exit], n: int = 601, eta: float = 1e-3
) -> str | None:
    """None if the disk r ≤ radius contains the well's part of {V < E_c} and meets no other part; else why not.

    Checked on an n × n grid over [−1.5 radius, 1.5 radius]² at the level E_c (1 − eta) (so that the parts
    touching at the saddles are apart on the grid); points within 5 % of radius of an exit's saddle are left
    out of the "meets no other part" test.
    """
    from scipy import ndimage  # deferred: scipy.ndimage loads on first use

    L = 1.5 * radius
    g = np.linspace(-L, L, n)
    h = g[1] - g[0]
    X, Y = np.meshgrid(g, g)
    inside = land.v(X, Y) < critical_energy * (1 - eta)
    lab, _ = ndimage.label(inside)
    mid = n // 2
    w = lab[mid, mid]
    r = np.hypot(X, Y)
    well = lab == w
    if well[0, :].any() or well[-1, :].any() or well[:, 0].any() or well[:, -1].any():
        return f"the well's part of V < E_c reaches beyond r = {L:.4g}"
    if r[well].max() > radius + 2 * h:
        return f"the well's part of V < E_c reaches r = {r[well].max():.4g} > {radius:.4g}"
    other = inside & ~well & (r < radius - 2 * h)
    for e in exits:
        other &= np.hypot(X - e.x, Y - e.y) > 0.05 * radius
    if other.any():
        k = np.argmax(other)
        return f"the disk r ≤ {radius:.4g} meets another part of V < E_c, e.g. at ({X.flat[k]:.4g}, {Y.flat[k]:.4g})"
    return None


# -- everything ------------------------------------------------------------------------------------------
def _given_exits(land: Landscape, exits) -> tuple[Exit, ...]:
    rows = []
    for k, e in enumerate(exits):
        if isinstance(e, Exit):
            rows.append((k, e, None))
            continue
        try:
            vals = [float(v) for v in e]
        except (TypeError, ValueError):
            raise ConfigError(f"exits[{k}] must be [x, y] or [x, y, energy], got {e!r}") from None
        if len(vals) not in (2, 3) or not all(math.isfinite(v) for v in vals):
            raise ConfigError(f"exits[{k}] must be [x, y] or [x, y, energy] of finite numbers, got {e!r}")
        rows.append((k, e, vals))
    if not rows:
        raise ConfigError("exits: give at least one exit [x, y] (or [x, y, energy])")
    out = []
    for k, e, vals in rows:  # each a critical point of V at its stated energy
        if vals is None:
            out.append(e)
            continue
        v = float(land.v(vals[0], vals[1]))
        energy = vals[2] if len(vals) == 3 else v
        gx, gy = (float(g) for g in land.gradient(vals[0], vals[1]))
        hess = max((abs(float(h)) for h in land.hessian(vals[0], vals[1])), default=0.0)
        r = math.hypot(vals[0], vals[1])
        if not (math.isfinite(v) and math.isfinite(gx) and math.isfinite(gy)) or math.hypot(gx, gy) > GIVEN_TOL * (
            1.0 + hess * r + abs(v)
        ):
            raise ConfigError(
                f"exits[{k}] = {e!r} is not a critical point of V (|∇V| = {math.hypot(gx, gy):.3g}, "
                f"V = {v:.10g} there): an exit is a saddle orbits leave through, where ∇V = 0"
            )
        if abs(v - energy) > GIVEN_TOL * max(1.0, abs(v)):
            raise ConfigError(f"exits[{k}] = {e!r}: its energy {energy!r} is not V there, {v!r}")
        out.append(Exit(vals[0], vals[1], energy))
    return tuple(_channel_order(out))


def _derived_exits(land: Landscape) -> tuple[tuple[CriticalPoint, ...], str, tuple[Exit, ...]]:
    """(critical points, method, exits) from the potential alone (module docstring, steps 1-4); ConfigError where
    it cannot decide."""
    points, method = critical_points(land)
    check_well(land, points)
    scale = max([p.distance for p in points if p.kind != "minimum"] or [1.0])
    found = find_exits(land, points, scale)
    top = max((e.energy for e in found), default=math.inf)
    bad = [p for p in points if p.kind == "degenerate" and p.energy <= top]
    if bad:
        p = bad[0]
        raise ConfigError(
            f"degenerate critical point at ({p.x:.6g}, {p.y:.6g}) with V = {p.energy:.6g} "
            f"(Hessian eigenvalues {p.eigenvalues[0]:.3g}, {p.eigenvalues[1]:.3g}): cannot tell "
            "whether orbits from the well leave through it; give `critical_energy` and `exits` "
            "in [system]"
        )
    if not found:
        listed = ", ".join(f"{p.kind} at ({p.x:.4g}, {p.y:.4g}) V = {p.energy:.4g}" for p in points) or "none"
        raise ConfigError(
            f"no exit: the potential has no saddle through which orbits from the well reach "
            f"infinity (critical points: {listed}); an escape over an asymptotic threshold, with no "
            "saddle, has no exit to give"
        )
    return points, method, found


def _same_exits(a: Sequence[Exit], b: Sequence[Exit]) -> bool:
    """The same saddles (positions and energies within GIVEN_TOL), whatever the order."""

    def close(e, f):
        return math.hypot(e.x - f.x, e.y - f.y) <= GIVEN_TOL * (1 + e.distance) * 100 and abs(
            e.energy - f.energy
        ) <= GIVEN_TOL * max(1.0, abs(f.energy))

    return len(a) == len(b) and all(any(close(e, f) for f in b) for e in a)


def _show_exits(exits: Sequence[Exit]) -> str:
    return "[" + ", ".join(f"[{e.x:.6g}, {e.y:.6g}, {e.energy:.6g}]" for e in exits) + "]"


def derive(
    expr, *, critical_energy: float | None = None, exits: Sequence | None = None, omega_radius: float | None = None
) -> Derivation:
    """Derive the critical points, exits, E_c and Ω of a potential (module docstring), with overrides.

    Parameters
    ----------
    expr : sympy.Expr
        V in x and y (parameters substituted: :func:`hhscatter.model.parse.substitute`).
    critical_energy : float, optional
        E_c given: > 0 and equal to the lowest exit's energy (derived or given), else refused (a contradiction).
    exits : sequence of [x, y] or [x, y, energy] or Exit, optional
        The exits given (energy V(x, y) when left out): each must be a critical point of V with V = its energy;
        where the derivation can decide, they must be the derived exits.
    omega_radius : float, optional
        Ω's radius given: the disk must hold the well's part of {V < E_c} and meet no other part
        (:func:`check_omega`).

    Returns
    -------
    Derivation

    Raises
    ------
    ConfigError
        The well's minimum not at the origin with V = 0; critical points forming a curve; a degenerate
        critical point below the highest exit's energy; no exit; Ω not a disk; each naming the key to give.

    Examples
    --------
    >>> from hhscatter.model.parse import parse_potential, substitute
    >>> d = derive(substitute(parse_potential("x**2/2 + y**2/2 - eps*x**2*y**2", {"eps": 0.25}), {"eps": 0.25}))
    >>> d.critical_energy, [(round(e.x, 12), round(e.y, 12)) for e in d.exits], d.omega_radius
    (1.0, [(1.414213562373, 1.414213562373), (-1.414213562373, 1.414213562373), (-1.414213562373, -1.414213562373), (1.414213562373, -1.414213562373)], 2.0)
    """
    t0 = time.perf_counter()
    land = Landscape(expr)
    if exits is not None:
        found = _given_exits(land, exits)
        points: tuple[CriticalPoint, ...] = ()
        method = "given"
        check_well(land, [])
        try:  # where the derivation can decide, the given exits must be the derived ones
            derived = _derived_exits(land)[2]
        except ConfigError:
            derived = None
        if derived is not None and not _same_exits(found, derived):
            raise ConfigError(
                f"exits {_show_exits(found)} contradict the derivation, which finds the exits "
                f"{_show_exits(derived)}; leave `exits` out of [system] (it is derived) or correct it"
            )
    else:
        points, method, found = _derived_exits(land)
    lowest = min(e.energy for e in found)
    ec = lowest if critical_energy is None else float(critical_energy)
    if not (math.isfinite(ec) and ec > 0):
        raise ConfigError(f"critical_energy must be a finite number > 0, got {ec!r}")
    if abs(ec - lowest) > GIVEN_TOL * max(1.0, abs(lowest)):
        source = "given" if exits is not None else "derived"
        raise ConfigError(
            f"critical_energy = {ec!r} contradicts the exits: E_c is the lowest exit's energy, "
            f"{lowest!r} (exits {source}); leave `critical_energy` out of [system] or correct it"
        )
    at_ec = [e for e in found if e.energy <= ec * (1 + 1e-12)] or list(found)
    if omega_radius is None:
        omega = max(e.distance for e in at_ec)
        why = check_omega(land, omega, ec, found)
        if why:
            raise ConfigError(
                f"Ω cannot be derived as a disk about the origin ({why}); give `omega_radius` in [system]"
            )
    else:
        omega = float(omega_radius)
        if not (math.isfinite(omega) and omega > 0):
            raise ConfigError(f"omega_radius must be a finite number > 0, got {omega_radius!r}")
        why = check_omega(land, omega, ec, found)
        if why:
            guess = max(e.distance for e in at_ec)
            derived_omega = "" if check_omega(land, guess, ec, found) else f"; the derivation finds {guess:.10g}"
            raise ConfigError(
                f"omega_radius = {omega!r} is not a radius of Ω, which must hold the well's part of "
                f"{{V < E_c}} and meet no other part: {why}{derived_omega}"
            )
    return Derivation(points, found, ec, omega, method, time.perf_counter() - t0)


__all__ = [
    "CriticalPoint",
    "DEGENERATE",
    "Derivation",
    "Landscape",
    "MAX_DESCENT_STEPS",
    "NO_RETURN_MARGIN",
    "SEARCH_RADIUS",
    "check_omega",
    "check_well",
    "critical_points",
    "derive",
    "find_exits",
    "no_return_radius",
]
