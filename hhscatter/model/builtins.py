"""The built-in systems and :func:`make_system`, the one entry point from a ``[system]`` table, the CLI or the API.

| name | V(x, y) | parameters (default) | E_c | exits |
|---|---|---|---|---|
| ``henon_heiles`` | ω²(x² + y²)/2 + λ(x²y − y³/3) | ω = 1, λ = 1 | ω⁶/(6λ²) | 3 saddles at distance ω²/λ |
| ``n_exit`` | r²/2 + rⁿ sin(nθ)/n = (x² + y²)/2 + Im((x + iy)ⁿ)/n | n = 3 (3 ≤ n ≤ 8) | (n − 2)/(2n) | n saddles at distance 1 |
| ``contopoulos`` | (x² + y²)/2 − εx²y² | ε = 0.25 | 1/(4ε) | 4 saddles on the diagonals at distance 1/√ε |
| ``barbanis`` | (x² + y²)/2 − εxy² | ε = 0.5 | 1/(8ε²) | 2 saddles at (1/(2ε), ±1/(√2 ε)) |

``henon_heiles`` is the closed-form :class:`~hhscatter.model.HenonHeiles` (the engine's tables unchanged
byte for byte); the others are :class:`~hhscatter.model.declared.DeclaredSystem` with the built-in's name,
whose E_c, exits and Ω are derived (and tested against the closed forms above). ``n_exit`` with n = 3 is
Hénon–Heiles written as a declared potential.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from hhscatter.errors import ConfigError
from hhscatter.model.base import DISSIPATIONS, System
from hhscatter.model.declared import OVERRIDES, DeclaredSystem
from hhscatter.model.henon_heiles import HenonHeiles

#: largest n of ``n_exit`` (the symbolic derivation's cost grows with n: ~3 s at n = 8)
MAX_N_EXIT = 8


@dataclass(frozen=True)
class Builtin:
    """A built-in system: its factory, its parameters with their types and defaults, one line of description.

    Parameters
    ----------
    factory : callable
        ``factory(dissipation=..., **params) -> System``.
    params : dict of str to (type, default)
        The parameters the factory takes.
    summary : str
        V and E_c in one line.

    Examples
    --------
    >>> sorted(BUILTINS["contopoulos"].params)
    ['eps']
    """

    factory: Callable[..., System]
    params: dict[str, tuple[type, Any]]
    summary: str


def henon_heiles(omega: float = 1.0, lam: float = 1.0, dissipation: str = "linear") -> System:
    """Hénon–Heiles with closed forms (:class:`~hhscatter.model.HenonHeiles`), Eq. (eqn:hh_potential).

    Parameters
    ----------
    omega, lam : float
        ω > 0, λ > 0.
    dissipation : {'linear', 'quadratic'}
        The drag law.

    Returns
    -------
    HenonHeiles

    Examples
    --------
    >>> henon_heiles().critical_energy == 1 / 6
    True
    """
    try:
        return HenonHeiles(omega, lam, dissipation)
    except ValueError as e:
        raise ConfigError(f"henon_heiles: {e}") from None


def n_exit_potential(n: int) -> str:
    """V = r²/2 + rⁿ sin(nθ)/n as text in x, y: 0.5*(x**2 + y**2) + (Im((x + iy)ⁿ))/n expanded.

    Parameters
    ----------
    n : int
        The number of exits, n ≥ 3.

    Returns
    -------
    str

    Examples
    --------
    >>> n_exit_potential(3)
    '0.5*(x**2 + y**2) + (3*x**2*y - y**3)/3'
    """
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    x, y = sp.symbols("x y", real=True)
    im = sp.expand(sp.im(sp.expand((x + sp.I * y) ** n)))
    return f"0.5*(x**2 + y**2) + ({sp.sstr(im, order='lex')})/{n}"


def n_exit(n: int = 3, dissipation: str = "linear") -> System:
    """The n-exit generalisation of Hénon–Heiles, V = r²/2 + rⁿ sin(nθ)/n: E_c = (n − 2)/(2n), n saddles at r = 1.

    Parameters
    ----------
    n : int
        The number of exits, 3 ≤ n ≤ :data:`MAX_N_EXIT` (n = 3 is Hénon–Heiles).
    dissipation : {'linear', 'quadratic'}
        The drag law.

    Returns
    -------
    DeclaredSystem

    Examples
    --------
    >>> s = n_exit(4)
    >>> round(s.critical_energy, 15), len(s.exits)
    (0.25, 4)
    """
    if isinstance(n, bool) or not isinstance(n, int) or not 3 <= n <= MAX_N_EXIT:
        raise ConfigError(f"n_exit: n must be an integer from 3 to {MAX_N_EXIT}, got {n!r}")
    return DeclaredSystem(n_exit_potential(n), {}, dissipation, name="n_exit", builtin_params={"n": n})


def contopoulos(eps: float = 0.25, dissipation: str = "linear") -> System:
    """Contopoulos' four-exit potential V = (x² + y²)/2 − εx²y²: E_c = 1/(4ε), saddles (±1, ±1)/√(2ε).

    Parameters
    ----------
    eps : float
        ε > 0.
    dissipation : {'linear', 'quadratic'}
        The drag law.

    Returns
    -------
    DeclaredSystem

    Examples
    --------
    >>> contopoulos(0.25).critical_energy
    1.0
    """
    _positive("contopoulos", "eps", eps)
    return DeclaredSystem("0.5*(x**2 + y**2) - eps*x**2*y**2", {"eps": eps}, dissipation, name="contopoulos")


def barbanis(eps: float = 0.5, dissipation: str = "linear") -> System:
    """A Barbanis-type two-exit potential V = (x² + y²)/2 − εxy²: E_c = 1/(8ε²), saddles (1/(2ε), ±1/(√2 ε)).

    Parameters
    ----------
    eps : float
        ε > 0.
    dissipation : {'linear', 'quadratic'}
        The drag law.

    Returns
    -------
    DeclaredSystem

    Examples
    --------
    >>> s = barbanis(0.5)
    >>> round(s.critical_energy, 15), [(round(e.x, 12), round(e.y, 12)) for e in s.exits]
    (0.5, [(1.0, 1.414213562373), (1.0, -1.414213562373)])
    """
    _positive("barbanis", "eps", eps)
    return DeclaredSystem("0.5*(x**2 + y**2) - eps*x*y**2", {"eps": eps}, dissipation, name="barbanis")


def _positive(system: str, key: str, value: float) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value > 0):
        raise ConfigError(f"{system}: {key} must be a finite number > 0, got {value!r}")


#: the built-in systems, name → :class:`Builtin`
BUILTINS: dict[str, Builtin] = {
    "henon_heiles": Builtin(
        henon_heiles, {"omega": (float, 1.0), "lam": (float, 1.0)}, "ω²(x² + y²)/2 + λ(x²y − y³/3); E_c = ω⁶/(6λ²)"
    ),
    "n_exit": Builtin(n_exit, {"n": (int, 3)}, "r²/2 + rⁿ sin(nθ)/n; E_c = (n − 2)/(2n)"),
    "contopoulos": Builtin(contopoulos, {"eps": (float, 0.25)}, "(x² + y²)/2 − εx²y²; E_c = 1/(4ε)"),
    "barbanis": Builtin(barbanis, {"eps": (float, 0.5)}, "(x² + y²)/2 − εxy²; E_c = 1/(8ε²)"),
}


def _typed(system: str, key: str, kind: type, value: Any) -> Any:
    if kind is int:
        if isinstance(value, bool) or not (isinstance(value, int) or (isinstance(value, float) and value.is_integer())):
            raise ConfigError(f"{system}: parameter {key!r} must be an integer, got {value!r}")
        return int(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{system}: parameter {key!r} must be a number, got {value!r}")
    return float(value)


def make_system(
    name: str | None = None,
    potential: Any = None,
    params: Mapping[str, Any] | None = None,
    dissipation: str = "linear",
    **overrides: Any,
) -> System:
    """The system of a ``[system]`` table (or the CLI's ``--system``/``--param``, or the API): a built-in or declared.

    Parameters
    ----------
    name : str, optional
        A built-in's name (:data:`BUILTINS`); neither ``name`` nor ``potential``: ``henon_heiles``.
    potential : str, sympy.Expr or heyoka.expression, optional
        A declared potential V(x, y) (:class:`~hhscatter.model.declared.DeclaredSystem`).
    params : mapping of str to float, optional
        The built-in's parameters, or the declared potential's.
    dissipation : {'linear', 'quadratic'}
        The drag law: −γp (default) or −γ|p|p.
    **overrides
        For a declared potential only: ``critical_energy``, ``exits``, ``omega_radius`` when the derivation
        cannot decide.

    Returns
    -------
    System

    Raises
    ------
    ConfigError
        Both ``name`` and ``potential``; an unknown built-in (the message lists them), an unknown or mistyped
        parameter of a built-in; an override for a built-in or an unknown override key; an unknown
        dissipation law; every error of :class:`~hhscatter.model.declared.DeclaredSystem`.

    Examples
    --------
    >>> make_system().name, make_system("contopoulos", params={"eps": 0.5}).critical_energy
    ('henon_heiles', 0.5)
    >>> make_system(potential="0.5*(x**2 + y**2) - eps*x*y**2", params={"eps": 0.5}).exits[0]
    Exit(x=1.0, y=1.4142135623730951, energy=0.5)
    """
    if dissipation not in DISSIPATIONS:
        raise ConfigError(f"system.dissipation must be one of {DISSIPATIONS}, got {dissipation!r}")
    unknown = sorted(set(overrides) - set(OVERRIDES))
    if unknown:
        raise ConfigError(
            f"system: unknown key(s) {unknown} (allowed: name, potential, params, dissipation, {', '.join(OVERRIDES)})"
        )
    if name is not None and potential is not None:
        raise ConfigError("system: give either `name` (a built-in) or `potential` (a declared potential), not both")
    if potential is not None:
        return DeclaredSystem(potential, params, dissipation, **overrides)
    name = "henon_heiles" if name is None else name
    if name not in BUILTINS:
        raise ConfigError(
            f"system.name: unknown built-in {name!r} (built-ins: {', '.join(BUILTINS)}; or give `potential`)"
        )
    if overrides:
        raise ConfigError(
            f"system: {sorted(overrides)} cannot be given for the built-in {name!r} (its E_c, exits "
            "and Ω are closed forms or derived); declare the potential instead"
        )
    spec = BUILTINS[name]
    params = dict(params or {})
    bad = sorted(set(params) - set(spec.params))
    if bad:
        raise ConfigError(
            f"system.params: unknown parameter(s) {bad} of {name!r} (its parameters: "
            f"{', '.join(spec.params) or 'none'})"
        )
    typed = {k: _typed(name, k, kind, params.get(k, default)) for k, (kind, default) in spec.params.items()}
    return spec.factory(dissipation=dissipation, **typed)


__all__ = [
    "BUILTINS",
    "Builtin",
    "MAX_N_EXIT",
    "barbanis",
    "contopoulos",
    "henon_heiles",
    "make_system",
    "n_exit",
    "n_exit_potential",
]
