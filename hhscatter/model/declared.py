"""A system declared as data: V(x, y) as text (or a sympy/heyoka expression), its parameters and the drag law.

:class:`DeclaredSystem` implements the :class:`~hhscatter.model.base.System` contract from the expression
alone: the expression is parsed safely (:mod:`hhscatter.model.parse`), E_c, the exits and Ω are derived at
construction (:mod:`hhscatter.model.derive`; each can be given instead), R(E) on demand. The heyoka
expressions of V and of the force −∇V are built by walking the sympy expressions (the force from the
expanded gradient, so a declared Hénon–Heiles costs as many operations per Taylor step as the built-in).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from hhscatter.errors import ConfigError
from hhscatter.model.base import DISSIPATIONS, Exit, System
from hhscatter.model.derive import Derivation, _given_exits, derive
from hhscatter.model.landscape import Landscape, check_well, no_return_radius
from hhscatter.model.parse import check_params, parse_potential, substitute, symbols, to_heyoka

if TYPE_CHECKING:  # annotations only
    from numpy.typing import ArrayLike

    from hhscatter.model.landscape import CriticalPoint

#: the keys that override a derived quantity (a scene file's [system] table may give them)
OVERRIDES = ("critical_energy", "exits", "omega_radius")


#: a denominator D of V vanishes where √(|D| / max|D|) ≤ POLE_TOL (|D| ≤ 1e-14 of its largest value in the disk):
#: a pole there, or a force so large that the integrator would stop (DeclaredSystem.nonfinite_point)
POLE_TOL = 1e-7


class DeclaredSystem(System):
    """A system given by its potential V(x, y) and drag law; E_c, exits, Ω and R(E) derived (module docstring).

    Immutable; equal (and hashed alike) when name, potential text, parameters, dissipation and overrides are.

    Parameters
    ----------
    potential : str, sympy.Expr or heyoka.expression
        V in x, y and the parameters' names, e.g. ``"0.5*(x**2 + y**2) - eps*x**2*y**2"``; V's well minimum
        must sit at the origin with V(0, 0) = 0 (energy).
    params : mapping of str to float, optional
        The parameters' values: each used in V, each used one given.
    dissipation : {'linear', 'quadratic'}
        The drag law for γ > 0: −γp (default) or −γ|p|p.
    name : str
        ``"declared"``, or the built-in's name when a built-in constructs it.
    critical_energy : float, optional
        E_c, when the derivation cannot decide (energy).
    exits : sequence of [x, y] or [x, y, energy], optional
        The exits' saddles, when the derivation cannot decide (energy V(x, y) when left out).
    omega_radius : float, optional
        Ω's radius, when the derivation cannot decide (length).
    builtin_params : mapping of str to float, optional
        The built-in's own parameters when they are not the potential's (n of ``n_exit``), for the provenance.

    Raises
    ------
    ConfigError
        Bad potential or parameters (:func:`~hhscatter.model.parse.parse_potential`), the well not at the
        origin, a quantity that cannot be derived (the message names the key to give), an unknown
        dissipation law.

    Examples
    --------
    >>> s = DeclaredSystem("0.5*(x**2 + y**2) - eps*x**2*y**2", {"eps": 0.25})
    >>> s.critical_energy, len(s.exits), s.omega_radius
    (1.0, 4, 2.0)
    >>> round(s.scalar_energy()(0.5, 0.0, 0.0, 1.0), 12)
    0.625
    """

    def __init__(
        self,
        potential: Any,
        params: Mapping[str, float] | None = None,
        dissipation: str = "linear",
        *,
        name: str = "declared",
        critical_energy: float | None = None,
        exits: Sequence | None = None,
        omega_radius: float | None = None,
        builtin_params: Mapping[str, float] | None = None,
    ):
        if dissipation not in DISSIPATIONS:
            raise ConfigError(f"dissipation must be one of {DISSIPATIONS}, got {dissipation!r}")
        values = check_params(params)
        expr = parse_potential(potential, values)
        set_ = object.__setattr__
        set_(self, "_name", str(name))
        set_(self, "_params", values)
        set_(self, "dissipation", dissipation)
        set_(self, "_text", potential.strip() if isinstance(potential, str) else str(expr))
        set_(self, "_expr", expr)
        set_(self, "_numeric", substitute(expr, values))
        set_(
            self,
            "_overrides",
            {
                k: v
                for k, v in (("critical_energy", critical_energy), ("exits", exits), ("omega_radius", omega_radius))
                if v is not None
            },
        )
        set_(self, "_builtin_params", dict(builtin_params) if builtin_params is not None else None)
        set_(
            self,
            "_derivation",
            derive(self._numeric, critical_energy=critical_energy, exits=exits, omega_radius=omega_radius),
        )
        set_(self, "_cache", {})

    # -- immutability, equality, pickling --------------------------------------------------------------------
    def __setattr__(self, key, value):
        raise AttributeError(f"DeclaredSystem is immutable (cannot set {key!r})")

    def __delattr__(self, key):
        raise AttributeError(f"DeclaredSystem is immutable (cannot delete {key!r})")

    def _key(self) -> str:
        return json.dumps(self.provenance(), sort_keys=True, default=repr)

    def __eq__(self, other):
        return isinstance(other, DeclaredSystem) and self._key() == other._key()

    def __hash__(self):
        return hash(self._key())

    def __repr__(self):
        extra = "".join(f", {k}={v!r}" for k, v in self._overrides.items())
        return f"DeclaredSystem({self._text!r}, {self._params!r}, {self.dissipation!r}, name={self._name!r}{extra})"

    def __reduce__(self):
        # rebuilt from its text with the derived quantities given: no second derivation in a worker
        d = self._derivation
        state = {
            "critical_energy": d.critical_energy,
            "omega_radius": d.omega_radius,
            "exits": [(e.x, e.y, e.energy) for e in d.exits],
        }
        return (
            _restore,
            (self._text, self._params, self.dissipation, self._name, self._overrides, self._builtin_params, state),
        )

    # -- identity ----------------------------------------------------------------------------------------------
    @property
    def name(self) -> str:
        return self._name

    @property
    def params(self) -> dict[str, float]:
        return dict(self._params)

    @property
    def potential_text(self) -> str:
        return self._text

    @property
    def expression(self) -> Any:
        """V as a sympy expression in x, y and the parameters' symbols."""
        return self._expr

    @property
    def derivation(self) -> Derivation:
        """What the derivation found (critical points, method, wall time)."""
        return self._derivation

    @property
    def critical_points(self) -> tuple[CriticalPoint, ...]:
        """The critical points of V found by the derivation (empty when the exits were given)."""
        return self._derivation.critical_points

    # -- derived quantities --------------------------------------------------------------------------------------
    @property
    def critical_energy(self) -> float:
        return self._derivation.critical_energy

    @property
    def exits(self) -> tuple[Exit, ...]:
        return self._derivation.exits

    @property
    def omega_radius(self) -> float:
        return self._derivation.omega_radius

    @property
    def _landscape(self) -> Landscape:
        if "land" not in self._cache:
            self._cache["land"] = Landscape(self._numeric)
        return self._cache["land"]

    def nonfinite_point(self, radius: float) -> tuple[float, float] | None:
        """:meth:`System.nonfinite_point`, cached per radius; None at once for a polynomial potential."""
        import sympy as sp  # deferred: sympy takes ~0.3 s to import

        if self._numeric.is_polynomial(*symbols()) and not self._numeric.atoms(sp.Function):
            return None
        key = ("nonfinite", float(radius))
        if key not in self._cache:
            self._cache[key] = super().nonfinite_point(radius) or self._pole(float(radius))
        return self._cache[key]

    def _pole(self, radius: float) -> tuple[float, float] | None:
        """A zero of a denominator of V in the disk r ≤ radius (a pole the grid of :meth:`nonfinite_point` can step
        over: 1/((x − a)² + (y − b)²) is finite at every grid point), or None.

        Each denominator of V (sympy's ``together``/``fraction``, and of every subexpression) is sampled on a
        polar grid; a sign change between neighbours, or a local minimum of |D| that reaches 0 (|D| ≤ POLE_TOL² of
        its largest value on the grid, by least squares on √|D| from the grid's smallest values), is a zero."""
        import sympy as sp  # deferred: sympy takes ~0.3 s to import
        from scipy.optimize import least_squares  # deferred: scipy loads on first use

        x, y = symbols()
        dens = {sp.fraction(sp.together(e))[1] for e in sp.preorder_traversal(self._numeric) if e.free_symbols}
        dens = [d for d in dens if d.free_symbols]
        r = np.linspace(0.0, radius, 201)
        th = np.linspace(0.0, 2 * np.pi, 361)
        R, T = np.meshgrid(r, th)
        X, Y = R * np.cos(T), R * np.sin(T)
        for den in dens:
            f = sp.lambdify((x, y), den, "numpy")
            with np.errstate(all="ignore"):
                D = np.broadcast_to(np.asarray(f(X, Y), dtype=float), X.shape)
            if not np.isfinite(D).all():
                continue  # not a real number there: the grid check of nonfinite_point answers for it
            scale = float(np.max(np.abs(D))) or 1.0
            sign = np.sign(D)
            for flips, (di, dj) in ((sign[:, 1:] * sign[:, :-1] <= 0, (0, 1)), (sign[1:] * sign[:-1] <= 0, (1, 0))):
                if flips.any():  # a zero between two neighbours (along r, or along θ)
                    i, j = np.argwhere(flips)[0]
                    return float(X[i + di, j + dj]), float(Y[i + di, j + dj])

            def root(z, f=f, scale=scale):  # √|D|: a double zero (a sum of squares) becomes a simple one
                return [math.sqrt(abs(float(f(z[0], z[1]))) / scale)]

            for k in np.argsort(np.abs(D), axis=None)[:8]:
                start = np.array([X.flat[k], Y.flat[k]])
                with np.errstate(all="ignore"):
                    sol = least_squares(root, start, xtol=1e-15, ftol=1e-15, gtol=1e-15)
                if np.hypot(*sol.x) <= radius and abs(sol.fun[0]) <= POLE_TOL:
                    return float(sol.x[0]), float(sol.x[1])
        return None

    def no_return_radius(self, energy: float) -> float:
        """R(E) ≥ the nearest saddle's distance, from :func:`hhscatter.model.landscape.no_return_radius` (cached)."""
        energy = float(energy)
        key = ("nrr", energy)
        if key not in self._cache:
            scale = max(e.distance for e in self.exits)
            self._cache[key] = max(no_return_radius(self._landscape, energy, scale), self.saddle_radius)
        return self._cache[key]

    # -- evaluations ------------------------------------------------------------------------------------------------
    def potential(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """V(x, y) on numpy arrays (energy)."""
        return self._landscape.v(x, y)

    def potential_expression(self, x: Any, y: Any, hy: Any) -> Any:
        """V as a heyoka expression of x, y (walked from the sympy expression, parameters as constants)."""
        return to_heyoka(self._numeric, x, y, hy)

    def force_expressions(self, x: Any, y: Any, hy: Any) -> tuple[Any, Any]:
        """(F_x, F_y) = −∇V from the expanded sympy gradient (no redundant products per Taylor step)."""
        import sympy as sp  # deferred: sympy takes ~0.3 s to import

        land = self._landscape
        return tuple(to_heyoka(sp.expand(-g), x, y, hy) for g in land.grad)

    def scalar_energy(self) -> Callable[[float, float, float, float], float]:
        """A plain-float H(x, y, px, py) (V lambdified with the math module from the sympy expression)."""
        if "scalar_v" not in self._cache:
            import sympy as sp  # deferred: sympy takes ~0.3 s to import

            self._cache["scalar_v"] = sp.lambdify(symbols(), self._numeric, "math")
        v = self._cache["scalar_v"]

        def energy(x, y, px, py):
            return 0.5 * (px * px + py * py) + v(x, y)

        return energy

    def force(self, x: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(F_x, F_y) = −∇V on numpy arrays, from the exact gradient (energy/length)."""
        gx, gy = self._landscape.gradient(x, y)
        return -gx, -gy

    @property
    def frequency(self) -> float:
        """√(largest eigenvalue of V's Hessian at the minimum) (1/time), from the exact Hessian."""
        return math.sqrt(max(self._landscape.classify(0.0, 0.0).eigenvalues[1], 0.0))

    def spec(self) -> dict[str, Any]:
        """The plain-data spec that rebuilds this system (:func:`hhscatter.model.spec.system_from_spec`).

        A built-in by name with its own parameters (n of ``n_exit``), a declared potential by its text; the
        overrides given at construction included.
        """
        if self._builtin_params is not None:
            out: dict[str, Any] = {"name": self._name, "params": dict(self._builtin_params)}
        elif self._name != "declared":
            out = {"name": self._name, "params": dict(self._params)}
        else:
            out = {"potential": self._text, "params": dict(self._params)}
        out["dissipation"] = self.dissipation
        for k, v in self._overrides.items():
            out[k] = (
                [[float(c) for c in (e if not isinstance(e, Exit) else (e.x, e.y, e.energy))] for e in v]
                if k == "exits"
                else float(v)
            )
        return out

    def provenance(self) -> dict[str, Any]:
        """Name, V as text, parameters, dissipation; the overrides and the built-in's parameters when given."""
        out = super().provenance()
        if self._builtin_params is not None:
            out["builtin_params"] = dict(self._builtin_params)
        for k, v in self._overrides.items():
            out[k] = (
                [list(map(float, e)) if not isinstance(e, Exit) else [e.x, e.y, e.energy] for e in v]
                if k == "exits"
                else float(v)
            )
        return out

    def hash_items(self) -> dict[str, Any]:
        """The provenance: every declared system enters the scene's hash."""
        return self.provenance()


def _restore(text, params, dissipation, name, overrides, builtin_params, state):
    """Unpickle a DeclaredSystem without deriving again (the derived quantities are given)."""
    self = DeclaredSystem.__new__(DeclaredSystem)
    values = check_params(params)
    expr = parse_potential(text, values)
    numeric = substitute(expr, values)
    land = Landscape(numeric)
    check_well(land, [])
    derivation = Derivation(
        (), _given_exits(land, state["exits"]), state["critical_energy"], state["omega_radius"], "given", 0.0
    )
    for key, value in (
        ("_name", name),
        ("_params", values),
        ("dissipation", dissipation),
        ("_text", text),
        ("_expr", expr),
        ("_numeric", numeric),
        ("_overrides", dict(overrides)),
        ("_builtin_params", builtin_params),
        ("_derivation", derivation),
        ("_cache", {"land": land}),
    ):
        object.__setattr__(self, key, value)
    return self


__all__ = ["DeclaredSystem", "OVERRIDES"]
