"""A declared potential as numbers: V, ∇V and its Hessian, its critical points and their kinds, the well's check
and the no-return radius R(E) (steps 1–3 and 6 of :func:`hhscatter.model.derive.derive`).

The critical points ∇V = 0 of a polynomial V are found symbolically (a lex Gröbner basis of (V_x, V_y): if it is
not zero-dimensional the critical points form curves and nothing can be derived; otherwise the real roots of its two
eliminants, polished by Newton's method); of any other V numerically (damped Newton from a polar grid of starts out
to :data:`SEARCH_RADIUS`, deduplicated). Their kind comes from the Hessian's eigenvalues (``minimum``, ``saddle``,
``maximum`` or ``degenerate``: an eigenvalue below :data:`DEGENERATE` of the largest). R(E)
(:func:`no_return_radius`) is the smallest R beyond which −∂V/∂r > 0 at every point with V ≤ E. Lengths and
energies in the potential's units.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import threading
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from hhscatter.errors import ConfigError
from hhscatter.model.parse import symbols

__all__ = [
    "DEGENERATE",
    "NO_RETURN_MARGIN",
    "SEARCH_RADIUS",
    "CriticalPoint",
    "Landscape",
    "check_well",
    "critical_points",
    "no_return_radius",
]

#: radius of the numeric critical-point search (non-polynomial potentials), in the potential's length units
SEARCH_RADIUS = 100.0
#: a Hessian eigenvalue below this fraction of the largest |eigenvalue| makes a critical point degenerate
DEGENERATE = 1e-8
#: relative margin added to R(E) beyond the refined grid estimate
NO_RETURN_MARGIN = 1e-9
#: seconds the symbolic search for critical points (lex Gröbner bases of ∇V) may take before the derivation is
#: refused (a dense polynomial with many-digit coefficients can take hours); ``HHSCATTER_DERIVE_SECONDS`` sets
#: another. Enforced in the main thread of the process that first builds the system (a run's workers rebuild it
#: from a scene already accepted, without a budget).
SYMBOLIC_BUDGET_SECONDS = 30.0
BUDGET_ENV = "HHSCATTER_DERIVE_SECONDS"


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


class _OverBudget(Exception):
    """The symbolic work ran past its budget (raised by the timer's signal inside sympy)."""


_unbounded = threading.local()


@contextlib.contextmanager
def unbounded_derivation():
    """Within this block the symbolic derivation has no time budget: for a process that rebuilds a system another
    process accepted (a run's worker), where a slower machine must not refuse it."""
    before = getattr(_unbounded, "on", False)
    _unbounded.on = True
    try:
        yield
    finally:
        _unbounded.on = before


def symbolic_budget() -> float | None:
    """The seconds the symbolic search may take here: :data:`SYMBOLIC_BUDGET_SECONDS` or ``$HHSCATTER_DERIVE_SECONDS``
    (ConfigError unless a number > 0); None inside :func:`unbounded_derivation`."""
    if getattr(_unbounded, "on", False):
        return None
    text = os.environ.get(BUDGET_ENV, "").strip()
    if not text:
        return SYMBOLIC_BUDGET_SECONDS
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ConfigError(f"{BUDGET_ENV} must be a number of seconds > 0, got {text!r}")
    return value


@contextlib.contextmanager
def _time_budget(seconds: float | None):
    """Raise _OverBudget in this block after ``seconds`` (a real-time timer; only in the main thread, and only
    when no other timer is running: elsewhere the block runs unbounded)."""
    usable = (
        seconds is not None
        and hasattr(signal, "setitimer")
        and threading.current_thread() is threading.main_thread()
        and signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    )
    if not usable:
        yield
        return

    def on_alarm(signum, frame):
        raise _OverBudget()

    before = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, before)


def _symbolic_candidates(land: Landscape) -> tuple[np.ndarray, np.ndarray]:
    """Every real solution of ∇V = 0 of a polynomial V: the real roots of the two lex eliminants, paired; a
    ConfigError when the Gröbner bases take longer than :func:`symbolic_budget`."""
    budget = symbolic_budget()
    try:
        with _time_budget(budget):
            return _symbolic_roots(land)
    except _OverBudget:
        raise ConfigError(
            f"the critical points of the potential were not derived within {budget:g} s (the symbolic "
            f"elimination of ∇V = 0 grows fast with the degree, the number of terms and the digits of the "
            f"coefficients; {BUDGET_ENV} sets another budget): give `critical_energy` and `exits` in [system], "
            "or a potential with fewer terms or shorter coefficients"
        ) from None


def _symbolic_roots(land: Landscape) -> tuple[np.ndarray, np.ndarray]:
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
