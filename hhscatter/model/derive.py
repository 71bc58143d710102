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
6. **R(E)** (:func:`no_return_radius`): the smallest R beyond which −∂V/∂r > 0 at every point with V ≤ E,
   from a polar grid refined by constrained optimisation (for Hénon–Heiles it reproduces √(6E)/ω).

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
from hhscatter.model.parse import symbols

#: radius of the numeric critical-point search (non-polynomial potentials), in the potential's length units
SEARCH_RADIUS = 100.0
#: a Hessian eigenvalue below this fraction of the largest |eigenvalue| makes a critical point degenerate
DEGENERATE = 1e-8
#: steps after which a steepest-descent path that has neither reached a minimum nor R(E) is given up
MAX_DESCENT_STEPS = 20_000
#: relative margin added to R(E) beyond the refined grid estimate
NO_RETURN_MARGIN = 1e-9
#: relative tolerance of a given override against what it is checked with (∇V = 0 at a given exit, its energy V
#: there, a given E_c against the lowest exit's energy, a given exit against a derived one)
GIVEN_TOL = 1e-8


@dataclass(frozen=True)
class CriticalPoint:
    """A critical point of V (∇V = 0).

    Parameters
    ----------
    x, y : float
        Position (length).
    energy : float
        V there (energy).
    kind : {'minimum', 'saddle', 'maximum', 'degenerate'}
        From the Hessian's eigenvalues.
    eigenvalues : tuple of float
        The Hessian's eigenvalues, ascending (energy/length²).

    Examples
    --------
    >>> CriticalPoint(0.0, 1.0, 1 / 6, "saddle", (-1.0, 3.0)).distance
    1.0
    """

    x: float
    y: float
    energy: float
    kind: str
    eigenvalues: tuple[float, float]

    @property
    def distance(self) -> float:
        """Distance from the origin (length)."""
        return math.hypot(self.x, self.y)


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


class Landscape:
    """Numeric V, ∇V and the Hessian of a sympy potential in x, y (numpy, lambdified from the expression).

    Parameters
    ----------
    expr : sympy.Expr
        V in the symbols x and y of :func:`hhscatter.model.parse.symbols` (no other free symbols).

    Examples
    --------
    >>> from hhscatter.model.parse import parse_potential
    >>> land = Landscape(parse_potential("x**2/2 + y**2/2 + x**2*y - y**3/3"))
    >>> float(land.v(0.0, 1.0)), land.polynomial
    (0.16666666666666669, True)
    """

    def __init__(self, expr):
        import sympy as sp  # deferred: sympy takes ~0.3 s to import

        x, y = symbols()
        self.expr, self.x, self.y = expr, x, y
        self.grad = (sp.diff(expr, x), sp.diff(expr, y))
        self.hess = (sp.diff(self.grad[0], x), sp.diff(self.grad[0], y), sp.diff(self.grad[1], y))
        # symbolic critical points for polynomials with rational coefficients (pi, sqrt(2)... go the numeric way)
        self.polynomial = bool(expr.is_polynomial(x, y)) and sp.Poly(expr, x, y).domain in (sp.ZZ, sp.QQ)
        # numpy arrays; scipy.special for what numpy lacks (erf)
        funcs = [sp.lambdify((x, y), e, ["scipy", "numpy"]) for e in (expr, *self.grad, *self.hess)]
        self._v, self._gx, self._gy, self._hxx, self._hxy, self._hyy = funcs
        #: (V_x, V_y) at one point in plain floats (the descent paths' right-hand side)
        self.scalar_gradient = sp.lambdify((x, y), self.grad, "math")

    @staticmethod
    def _arr(f, x, y) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        with np.errstate(all="ignore"):
            return np.asarray(f(x, y), dtype=float) + np.zeros(np.broadcast(x, y).shape)

    def v(self, x, y) -> np.ndarray:
        """V(x, y) (energy)."""
        return self._arr(self._v, x, y)

    def gradient(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """(V_x, V_y) (energy/length)."""
        return self._arr(self._gx, x, y), self._arr(self._gy, x, y)

    def hessian(self, x, y) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(V_xx, V_xy, V_yy) (energy/length²)."""
        return self._arr(self._hxx, x, y), self._arr(self._hxy, x, y), self._arr(self._hyy, x, y)

    def radial(self, x, y) -> np.ndarray:
        """r ∂V/∂r = x V_x + y V_y (energy): ≥ 0 where the radial force is not outward."""
        gx, gy = self.gradient(x, y)
        return np.asarray(x) * gx + np.asarray(y) * gy

    def newton(self, x, y, iterations: int = 60, max_step: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
        """Damped Newton iterations on ∇V = 0 for arrays of starts (steps capped at max_step·max(r, 0.1))."""
        x = np.array(x, dtype=float, copy=True)
        y = np.array(y, dtype=float, copy=True)
        for _ in range(iterations):
            gx, gy = self.gradient(x, y)
            a, b, c = self.hessian(x, y)
            with np.errstate(all="ignore"):
                det = a * c - b * b
                dx = -(c * gx - b * gy) / det
                dy = -(a * gy - b * gx) / det
                step = np.hypot(dx, dy)
                cap = max_step * np.maximum(np.hypot(x, y), 0.1)
                f = np.where(step > cap, cap / step, 1.0)
            ok = np.isfinite(dx) & np.isfinite(dy) & np.isfinite(f)
            x = np.where(ok, x + np.where(ok, f * dx, 0.0), x)
            y = np.where(ok, y + np.where(ok, f * dy, 0.0), y)
        return x, y

    def classify(self, x: float, y: float) -> CriticalPoint:
        """The critical point at (x, y) with its energy, Hessian eigenvalues and kind."""
        a, b, c = (float(h) for h in self.hessian(x, y))
        lo, hi = np.linalg.eigvalsh(np.array([[a, b], [b, c]]))
        big = max(abs(lo), abs(hi))
        if big == 0 or min(abs(lo), abs(hi)) < DEGENERATE * big:
            kind = "degenerate"
        elif lo > 0:
            kind = "minimum"
        elif hi < 0:
            kind = "maximum"
        else:
            kind = "saddle"
        return CriticalPoint(float(x), float(y), float(self.v(x, y)), kind, (float(lo), float(hi)))


# -- critical points ------------------------------------------------------------------------------
def _curve_error(extra: str = "") -> ConfigError:
    return ConfigError(
        "the critical points of the potential form a curve (∇V = 0 is not a finite set of points"
        f"{extra}): the exits cannot be derived; give `critical_energy` and `exits` in [system]"
    )


def _symbolic_candidates(land: Landscape) -> tuple[np.ndarray, np.ndarray]:
    """Every real solution of ∇V = 0 of a polynomial V: the real roots of the two lex eliminants, paired."""
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    x, y = land.x, land.y
    grad = [sp.expand(g) for g in land.grad]
    roots = {}
    for gens, var in (((x, y), y), ((y, x), x)):
        G = sp.groebner(grad, *gens, order="lex")
        if not G.is_zero_dimensional:
            raise _curve_error()
        uni = [g for g in G.exprs if g.free_symbols <= {var}]
        if not uni:
            raise _curve_error()
        poly = sp.Poly(uni[-1], var)
        roots[var] = sorted({float(r.evalf(30)) for r in poly.real_roots()}) if poly.degree() > 0 else []
    xs, ys = np.meshgrid(np.array(roots[x]), np.array(roots[y]))
    return xs.ravel(), ys.ravel()


def _numeric_candidates(land: Landscape) -> tuple[np.ndarray, np.ndarray]:
    """Damped-Newton limits from a polar grid of starts out to SEARCH_RADIUS."""
    r = np.geomspace(0.02, SEARCH_RADIUS, 48)
    th = np.linspace(0, 2 * np.pi, 40, endpoint=False) + 0.0123
    R, T = np.meshgrid(r, th)
    x0 = np.concatenate([[0.0], (R * np.cos(T)).ravel()])
    y0 = np.concatenate([[0.0], (R * np.sin(T)).ravel()])
    return land.newton(x0, y0, iterations=100)


def critical_points(land: Landscape) -> tuple[tuple[CriticalPoint, ...], str]:
    """critical_points(land) -> (points sorted by energy, "symbolic" or "numeric").

    Raises ConfigError when the critical points form a curve (a polynomial's Gröbner basis is not
    zero-dimensional).
    """
    if land.polynomial:
        xs, ys, method = *_symbolic_candidates(land), "symbolic"
    else:
        xs, ys, method = *_numeric_candidates(land), "numeric"
    xs, ys = land.newton(xs, ys, iterations=30, max_step=1e9)
    gx, gy = land.gradient(xs, ys)
    a, b, c = land.hessian(xs, ys)
    scale = 1.0 + np.abs(a) + np.abs(b) + np.abs(c)
    ok = np.isfinite(gx) & np.isfinite(gy) & (np.hypot(gx, gy) < 1e-9 * scale * (1 + np.hypot(xs, ys)))
    ok &= np.isfinite(land.v(xs, ys)) & np.isfinite(scale)  # (not where V itself is undefined: log, sqrt)
    if method == "numeric":
        ok &= np.hypot(xs, ys) <= SEARCH_RADIUS
    pts: list[tuple[float, float]] = []
    for px, py in zip(xs[ok], ys[ok]):
        px = 0.0 if abs(px) < 1e-14 else float(px)
        py = 0.0 if abs(py) < 1e-14 else float(py)
        if all(math.hypot(px - qx, py - qy) > 1e-7 * (1 + math.hypot(px, py)) for qx, qy in pts):
            pts.append((px, py))
    out = sorted((land.classify(px, py) for px, py in pts), key=lambda p: (p.energy, p.distance))
    return tuple(out), method


# -- the well ----------------------------------------------------------------------------------------
def check_well(land: Landscape, points: Sequence[CriticalPoint]) -> None:
    """The well's minimum must be a non-degenerate minimum at the origin with V(0, 0) = 0 (ConfigError)."""
    v0 = float(land.v(0.0, 0.0))
    gx, gy = (float(g) for g in land.gradient(0.0, 0.0))
    scale = max(1.0, *(abs(float(h)) for h in land.hessian(0.0, 0.0)))
    if not (math.isfinite(v0) and math.isfinite(gx) and math.isfinite(gy)):
        raise ConfigError(
            f"the potential is not finite at the origin (V(0, 0) = {v0}): the well's minimum must "
            "be at the origin with V = 0"
        )
    if math.hypot(gx, gy) > 1e-12 * scale:
        minima = [p for p in points if p.kind == "minimum"]
        near = min(minima, key=lambda p: p.distance, default=None)
        where = (
            f"found at ({near.x:.6g}, {near.y:.6g}) with V = {near.energy:.6g}"
            if near
            else f"∇V(0, 0) = ({gx:.3g}, {gy:.3g}) and no minimum was found"
        )
        raise ConfigError(f"the well's minimum must be at the origin, {where}; shift the potential")
    cp = land.classify(0.0, 0.0)
    if cp.kind != "minimum":
        raise ConfigError(
            f"the origin is a {cp.kind} critical point of the potential (Hessian eigenvalues "
            f"{cp.eigenvalues[0]:.3g}, {cp.eigenvalues[1]:.3g}), not a non-degenerate minimum: the "
            "well's minimum must be at the origin"
        )
    if abs(v0) > 1e-14 * max([1.0] + [abs(p.energy) for p in points]):
        raise ConfigError(f"the well's minimum must have V = 0, but V(0, 0) = {v0!r}; subtract it from the potential")


# -- the no-return radius --------------------------------------------------------------------------------
def no_return_radius(land: Landscape, energy: float, scale: float = 1.0) -> float:
    """R(E): the smallest R with −∂V/∂r > 0 at every point r ≥ R where V ≤ E (length).

    The "bad" set S = {V ≤ E, ρ ≥ 0} with ρ = x V_x + y V_y = r ∂V/∂r is scanned on a polar grid (720 angles ×
    1000 radii) out to r_max = 50·scale (×4 up to three times while S reaches 90 % of r_max). S's farthest point
    is where its boundary is farthest out: a corner (V = E and ρ = 0) or a point of the level curve V = E
    tangent to the circle (V = E and ∂V/∂θ = 0). Grid cells across which both functions of either pair change
    sign are polished by Newton's method; R is the farthest polished point in S, or, if a grid point of S lies
    beyond every one (a case neither pair describes), that grid point plus one radial step. A relative margin of
    :data:`NO_RETURN_MARGIN` is added. 0 when S is empty.

    Raises ConfigError when S reaches beyond 3200·scale: no no-return radius (the potential does not push
    outward far out, e.g. it is bounded there).
    """
    r_max = 50.0 * scale
    th = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    for _ in range(4):
        r = np.linspace(0, r_max, 1001)[1:]
        R, T = np.meshgrid(r, th)
        X, Y = R * np.cos(T), R * np.sin(T)
        f = land.v(X, Y) - energy
        gx, gy = land.gradient(X, Y)
        with np.errstate(all="ignore"):  # overflow far out: inf/nan compare False, as they should
            rho = X * gx + Y * gy
        bad = (f <= 0) & (rho >= 0)
        if not bad.any():
            return 0.0
        rb = float(R[bad].max())
        if rb < 0.9 * r_max:
            break
        r_max *= 4
    else:
        raise ConfigError(
            f"no no-return radius at E = {energy:.6g}: points with V ≤ E where the radial force "
            f"is not outward reach r = {r_max:.3g}; the potential must fall off outward in its exits"
        )
    dr = r[1] - r[0]
    with np.errstate(all="ignore"):
        tau = X * gy - Y * gx  # ∂V/∂θ

    def changes(F):  # cells (θ_i..θ_i+1, r_j..r_j+1) across which F changes sign (θ wraps round)
        c = np.stack([F[:, :-1], F[:, 1:], np.roll(F, -1, 0)[:, :-1], np.roll(F, -1, 0)[:, 1:]])
        return (c.min(axis=0) <= 0) & (c.max(axis=0) >= 0)

    best = 0.0
    fc = changes(f)
    for second in (rho, tau):
        cells = fc & changes(second)
        cells &= R[:, :-1] >= rb - 3 * dr  # only cells near the far end of S matter
        if not cells.any():
            continue
        x0, y0 = (X[:, :-1][cells] + X[:, 1:][cells]) / 2, (Y[:, :-1][cells] + Y[:, 1:][cells]) / 2
        x, y = _polish(land, x0, y0, energy, second is rho)
        f1 = land.v(x, y) - energy
        r1 = land.radial(x, y)
        ok = (np.abs(f1) <= 1e-10 * max(1.0, abs(energy))) & (r1 >= -1e-10 * max(1.0, abs(energy)))
        ok &= np.hypot(x - x0, y - y0) < 4 * dr
        if ok.any():
            best = max(best, float(np.hypot(x, y)[ok].max()))
    if rb > best:
        best = rb + dr  # S reaches beyond every polished point: the grid's resolution bound
    return best * (1 + NO_RETURN_MARGIN)


def _polish(land: Landscape, x, y, energy: float, corner: bool, iterations: int = 40):
    """Newton's method on (V − E, ρ) (corner) or (V − E, ∂V/∂θ) (tangent point), vectorised over starts."""
    x = np.array(x, dtype=float, copy=True)
    y = np.array(y, dtype=float, copy=True)
    for _ in range(iterations):
        gx, gy = land.gradient(x, y)
        a, b, c = land.hessian(x, y)
        f1 = land.v(x, y) - energy
        if corner:
            f2 = x * gx + y * gy
            j21, j22 = gx + x * a + y * b, gy + x * b + y * c
        else:
            f2 = x * gy - y * gx
            j21, j22 = gy + x * b - y * a, -gx + x * c - y * b
        with np.errstate(all="ignore"):
            det = gx * j22 - gy * j21
            dx = -(j22 * f1 - gy * f2) / det
            dy = -(gx * f2 - j21 * f1) / det
        ok = np.isfinite(dx) & np.isfinite(dy)
        x = np.where(ok, x + np.where(ok, dx, 0.0), x)
        y = np.where(ok, y + np.where(ok, dy, 0.0), y)
    return x, y


# -- exits -----------------------------------------------------------------------------------------------
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
