"""The energy-diffusion-limited escape rate of a well with several degrees of freedom, from its energy shells.

At weak drag the energy E = |p|²/2 + V of an orbit in the well changes slowly compared with its motion on the
energy shell. For dp = −∇V dt − γp dt + √(2γT) dW with n momenta (unit mass), Itô's rule gives
dE = γ(nT − |p|²) dt + √(2γT) p·dW; averaged over the shell (the orbit explores it: ergodicity), E diffuses with
D(E) = γT ⟨|p|²⟩_E, and the shell average is exact in the phase volume Ω(E) of the well below E:
g(E) ⟨|p|²⟩_E = n Ω(E), g = dΩ/dE (integrate p·∂H/∂p over the shell by parts). The density of E then obeys a
one-dimensional Fokker–Planck equation with the stationary density g(E) e^{−E/T} and the flux

    J = −γ T n Ω(E) e^{−E/T} ∂/∂E [ρ(E) e^{E/T} / g(E)]

(Hänggi, Talkner and Borkovec, Rev. Mod. Phys. 62, 251 (1990), energy diffusion in many dimensions and its
connection with unimolecular rate theory; Borkovec and Berne, J. Chem. Phys. 82, 794 (1985)). Two closures at
the barrier give two rates, each the lowest eigenvalue of that equation:

- **absorbing at the barrier** (``rate_absorbing``): an orbit escapes when its energy reaches the lowest saddle's
  E_b. With one degree of freedom Ω(E_b) = S, the action of the orbit at the barrier, and the rate tends to
  Kramers' energy-diffusion rate (γS/T)(ω_0/2π) e^{−ΔE/T} as ΔE/T grows; with n degrees of freedom its
  large-barrier form is k_abs = nγ Ω(E_b) e^{−E_b/T} / Z, Z = ∫ g e^{−E/T} dE.
- **the microcanonical flux above the barrier** (``rate``): above E_b an orbit crosses a saddle's dividing line
  at the microcanonical rate F(E)/g(E) (RRKM), F(E) = Σ_s A_s(E) the flux across the dividing lines, A_s(E) the
  phase area ∮ p dq of the motion along saddle s's dividing line at energy E; the equation gets that sink and a
  reflecting top. As γ grows this rate tends to the anharmonic transition-state rate
  k_TST = ∫ F e^{−E/T} dE / Z; as γ → 0 to the absorbing one.

The shell-averaged δ of the turnover theory (:mod:`hhscatter.analysis.noise.turnover`) is k_abs / k_TST: with
one degree of freedom it is γS/T.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import linalg, ndimage

from hhscatter.analysis.noise.kramers import hessian, kramers_langer, well_barrier
from hhscatter.analysis.noise.turnover import depopulation_factor
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "EnergyDiffusion",
    "WellShells",
    "energy_diffusion_rate",
    "is_separable",
    "thermal_well_shells",
    "well_energy_diffusion",
    "well_shells",
]


def energy_diffusion_rate(energies, phase_volume, gamma: float, temperature: float, *, dof: int = 2, flux=None):
    """energy_diffusion_rate(E, Ω, γ, T, dof=2, flux=None) -> the lowest eigenvalue (1/time) of the
    energy-diffusion equation of the module docstring on the grid ``energies``.

    ``energies``: an even grid from the well's minimum (energy); ``phase_volume``: Ω(E) on it (action^dof: the
    phase volume of the well below E, 0 at the minimum); ``dof``: the number n of momenta the drag acts on;
    ``flux``: F(E) on the grid (action^(dof−1)), the microcanonical flux out of the well, or None: the grid's last
    energy is then absorbing (an orbit escapes when its energy reaches it). Conservative finite volumes with
    Ω at the cells' edges (second order in the energy step). The symmetric eigenproblem is scaled by the
    Boltzmann weights: with a flux, its rounding error grows with γ (0.1 % at γ ≈ 10³/T in the units of the
    tests), far above the drag where energy diffusion limits the rate.

    Examples
    --------
    A one-dimensional harmonic well (ω = 1: Ω = 2πE) absorbing at ΔE/T = 8: close to Kramers' energy-diffusion
    rate γ (ΔE/T) e^{−ΔE/T} (δ k_TST with δ = γ 2πΔE/T):

    >>> E = np.linspace(0.0, 8.0, 4001)
    >>> k = energy_diffusion_rate(E, 2 * np.pi * E, 0.01, 1.0, dof=1)
    >>> round(k / (0.01 * 8 * math.exp(-8)), 2)
    0.86
    """
    e = check.numbers(energies, "energies", min_size=3)
    om = check.numbers(phase_volume, "phase_volume", min_size=3, minimum=0.0)
    if om.size != e.size:
        raise ConfigError(f"phase_volume must have the length of energies ({e.size}), got {om.size}")
    step = np.diff(e)
    if not (np.all(step > 0) and np.allclose(step, step[0], rtol=1e-9, atol=0)):
        raise ConfigError("energies must be an increasing, evenly spaced grid")
    check.number(gamma, "gamma", positive=True)
    check.number(temperature, "temperature", positive=True)
    dof = check.count(dof, "dof", 1)
    if flux is not None:
        f = check.numbers(flux, "flux", min_size=3, minimum=0.0)
        if f.size != e.size:
            raise ConfigError(f"flux must have the length of energies ({e.size}), got {f.size}")
    h = float(step[0])
    boltz = np.exp(-(e - e[0]) / temperature)
    mid = 0.5 * (e[1:] + e[:-1])
    om_mid = 0.5 * (om[1:] + om[:-1])  # Ω at the cells' edges (the trapezoid; Ω is smooth)
    # P = γTnΩ e^{−E/T} on the edges; the weights ∫ g e^{−E/T} over each node's cell
    p_edge = gamma * temperature * dof * om_mid * np.exp(-(mid - e[0]) / temperature)
    om_edges = np.concatenate([[om[0]], om_mid, [om[-1]]])
    w = np.diff(om_edges) * boltz
    diag = np.zeros(e.size)
    diag[:-1] += p_edge / h
    diag[1:] += p_edge / h
    off = -p_edge / h
    if flux is None:  # absorbing at the last energy: the unknowns are the nodes below it
        diag, off, w = diag[:-1], off[:-1], w[:-1]
    else:
        diag = diag + f * boltz * h  # the sink: w k(E) with k = F/g
    if not np.all(w > 0):
        raise ConfigError("phase_volume must increase strictly along energies (the well's shells hold phase volume)")
    s = 1.0 / np.sqrt(w)
    lam = linalg.eigh_tridiagonal(diag * s * s, off * s[:-1] * s[1:], select="i", select_range=(0, 0))[0]
    return float(lam[0])


@dataclass(frozen=True)
class WellShells:
    """The energy shells of a two-degree-of-freedom well: ``energies`` (an even grid from V(min) to ``top``,
    energy), ``phase_volume`` Ω(E) (action², the well below E bounded by the saddles' dividing lines), ``flux``
    F(E) = Σ_s A_s(E) (action) and ``flux_by_exit`` (one array per exit), ``barrier`` E_b (the lowest saddle's
    energy), ``top`` (the grid's last energy: the requested one or, lower, where a dividing line's transverse well
    would spill)."""

    energies: np.ndarray
    phase_volume: np.ndarray
    flux: np.ndarray
    flux_by_exit: tuple
    barrier: float
    top: float


def _dividing_line(model, e):
    """The saddle's unstable direction u (unit) and stable direction t (unit): the dividing line is e + s t."""
    ev, vec = np.linalg.eigh(hessian(model, float(e.x), float(e.y)))
    u, t = vec[:, 0], vec[:, 1]
    if u @ np.array([e.x, e.y]) < 0:  # u points out of the well (away from the minimum at the origin)
        u = -u
    return u, t


def well_shells(model, top: float, *, grid: int = 1201, n_energies: int = 4001) -> WellShells:
    """well_shells(model, top, grid=1201, n_energies=4001) -> WellShells: Ω(E) and F(E) of ``model``'s well on an
    even grid of ``n_energies`` energies from V(min) to ``top`` (energy).

    Ω(E) = 2π ∫ (E − V)₊ dx dy over the well: the connected region around the minimum (the origin) on the
    minimum's side of every saddle's dividing line (the straight line through the saddle along its Hessian's
    stable direction), by the midpoint rule on a ``grid`` × ``grid`` lattice of a square that grows until the
    region does not reach its edge. A_s(E) = 2 ∫ √(2 (E − V)) ds along the dividing line over the interval around
    the saddle where V < E. ``top`` is lowered to where a dividing line's interval would spill (the largest V on
    either side of the saddle within 4 saddle distances).

    Examples
    --------
    Hénon–Heiles: at E_b = 1/6 the well is the triangle of the three saddles; along the dividing line y = 1,
    V = 1/6 + 3x²/2, so A(E) = 2π(E − 1/6)/√3 per saddle:

    >>> from hhscatter.model import HenonHeiles
    >>> sh = well_shells(HenonHeiles(), 0.25, n_energies=501)
    >>> round(float(np.interp(1 / 6, sh.energies, sh.phase_volume)), 4), sh.top
    (0.6122, 0.25)
    >>> round(float(sh.flux_by_exit[0][-1]) / (2 * math.pi * (0.25 - 1 / 6) / math.sqrt(3)), 4)
    1.0
    """
    check.system(model)
    top = check.number(top, "top", positive=False)
    grid = check.count(grid, "grid", 51)
    n_energies = check.count(n_energies, "n_energies", 3)
    v0 = float(model.potential(np.array(0.0), np.array(0.0)))
    e_b = v0 + well_barrier(model)
    if not top > e_b:
        raise ConfigError(f"top must be above the lowest saddle's energy {e_b:g}, got {top!r}")
    exits = list(model.exits)
    lines = [_dividing_line(model, e) for e in exits]
    scale = max(math.hypot(float(e.x), float(e.y)) for e in exits)
    # the transverse wells along the dividing lines: each A_s on the interval around the saddle where V < E
    s = np.linspace(-4 * scale, 4 * scale, 8001)
    ds = float(s[1] - s[0])
    profiles = []
    for e, (_, t) in zip(exits, lines):
        vl = np.asarray(model.potential(float(e.x) + s * t[0], float(e.y) + s * t[1]), dtype=float)
        c = s.size // 2
        right, left = np.maximum.accumulate(vl[c:]), np.maximum.accumulate(vl[c::-1])
        top = min(top, float(right[-1]), float(left[-1]))
        profiles.append((vl, c, right, left))
    # the well on a lattice: the component of the minimum below `top`, cut at the dividing lines
    half = 1.5 * scale
    for _ in range(8):
        xs = np.linspace(-half, half, grid)
        x, y = np.meshgrid(xs, xs, indexing="ij")
        v = np.asarray(model.potential(x, y), dtype=float)
        inside = v < top
        for e, (u, _) in zip(exits, lines):
            inside &= (x - float(e.x)) * u[0] + (y - float(e.y)) * u[1] <= 0
        labels, _ = ndimage.label(inside)
        comp = labels == labels[grid // 2, grid // 2]
        if not (comp[0].any() or comp[-1].any() or comp[:, 0].any() or comp[:, -1].any()):
            break
        half *= 2
    else:
        raise ConfigError(f"the well's region below top = {top:g} reaches every lattice tried: lower top")
    if not top > e_b:
        raise ConfigError(f"the well spills at {top:g}, not above the lowest saddle's energy {e_b:g}")
    cell = float(xs[1] - xs[0]) ** 2
    vs = np.sort(v[comp])
    cums = np.concatenate([[0.0], np.cumsum(vs)])
    energies = np.linspace(v0, top, n_energies)
    k = np.searchsorted(vs, energies)
    omega = 2 * math.pi * cell * (energies * k - cums[k])
    by_exit = []
    for vl, c, right, left in profiles:
        a = np.zeros(n_energies)
        for i in np.nonzero(energies > vl[c])[0]:
            en = energies[i]
            hi, lo = c + int(np.searchsorted(right, en)), c - int(np.searchsorted(left, en))
            a[i] = 2 * ds * float(np.sqrt(2 * np.clip(en - vl[lo + 1 : hi], 0.0, None)).sum())
        by_exit.append(a)
    return WellShells(energies, omega, np.sum(by_exit, axis=0), tuple(by_exit), e_b, float(top))


@dataclass(frozen=True)
class EnergyDiffusion:
    """The energy-diffusion rates of a well at (γ, T) (1/time; module docstring): ``rate`` (with the
    microcanonical flux above the barrier), ``rate_absorbing`` (absorbing at E_b), ``absorbing_limit`` (its
    large-barrier form nγΩ(E_b) e^{−E_b/T}/Z), ``transition_state`` (the anharmonic k_TST = ∫F e^{−E/T} dE/Z,
    the γ → ∞ limit of ``rate``), ``delta`` (the shell-averaged δ = absorbing_limit / transition_state,
    dimensionless), ``turnover`` = Υ(δ) k_KL (the Mel'nikov–Meshkov/PGH rate on that δ), ``phase_volume_barrier``
    Ω(E_b) (action²) and ``top`` (the grid's last energy)."""

    gamma: float
    temperature: float
    rate: float
    rate_absorbing: float
    absorbing_limit: float
    transition_state: float
    delta: float
    turnover: float
    phase_volume_barrier: float
    top: float


def well_energy_diffusion(
    model,
    gamma: float,
    temperature: float,
    *,
    above: float = 12.0,
    grid: int = 1201,
    n_energies: int = 4001,
    shells: WellShells | None = None,
) -> EnergyDiffusion:
    """well_energy_diffusion(model, γ, T) -> EnergyDiffusion: the energy-diffusion rates of ``model``'s well
    (two degrees of freedom, unit mass, the drag −γp on both momenta) at drag γ (1/time) and temperature T
    (energy), from :func:`well_shells` up to E_b + ``above`` T (or where the well spills) and
    :func:`energy_diffusion_rate`; ``shells``: those of an earlier call (its ``top`` is kept).

    Examples
    --------
    Hénon–Heiles at ΔE/T = 3: at γ = 0.003 the flux above the barrier slows the escape below the absorbing
    closure; at large γ the rate reaches the anharmonic transition-state rate:

    >>> from hhscatter.model import HenonHeiles
    >>> m = HenonHeiles()
    >>> sh = well_shells(m, 1 / 6 + 12 / 18, n_energies=1001)
    >>> ed = well_energy_diffusion(m, 0.003, 1 / 18, shells=sh)
    >>> round(ed.rate * 1e4, 2), round(ed.rate_absorbing * 1e4, 2), round(float(ed.delta), 3)
    (8.87, 14.36, 0.109)
    >>> fast = well_energy_diffusion(m, 300.0, 1 / 18, shells=sh)
    >>> round(fast.rate / fast.transition_state, 3)
    1.0
    """
    check.system(model)
    check.number(gamma, "gamma", positive=True)
    check.number(temperature, "temperature", positive=True)
    check.number(above, "above", positive=True)
    if shells is None:
        e_b = float(model.potential(np.array(0.0), np.array(0.0))) + well_barrier(model)
        shells = well_shells(model, e_b + above * temperature, grid=grid, n_energies=n_energies)
    e, om, f = shells.energies, shells.phase_volume, shells.flux
    i_b = int(np.searchsorted(e, shells.barrier))
    # the absorbing closure on a grid that ends at E_b: Ω interpolated there (it is smooth)
    e_abs = np.linspace(e[0], shells.barrier, i_b + 1)
    om_abs = np.interp(e_abs, e, om)
    boltz = np.exp(-(e - e[0]) / temperature)
    z = float(np.sum(np.diff(om) * 0.5 * (boltz[1:] + boltz[:-1]))) + om[-1] * boltz[-1]
    k_tst = float(np.sum(0.5 * (f[1:] * boltz[1:] + f[:-1] * boltz[:-1]) * np.diff(e))) / z
    om_b = float(np.interp(shells.barrier, e, om))
    k_abs_limit = 2 * gamma * om_b * math.exp(-(shells.barrier - e[0]) / temperature) / z
    delta = float(k_abs_limit / k_tst)
    kl = kramers_langer(model, gamma, temperature)
    return EnergyDiffusion(
        gamma=gamma,
        temperature=temperature,
        rate=energy_diffusion_rate(e, om, gamma, temperature, dof=2, flux=f),
        rate_absorbing=energy_diffusion_rate(e_abs, om_abs, gamma, temperature, dof=2),
        absorbing_limit=float(k_abs_limit),
        transition_state=float(k_tst),
        delta=delta,
        turnover=float(depopulation_factor(delta)) * kl.rate,
        phase_volume_barrier=om_b,
        top=shells.top,
    )


_THERMAL_SHELLS: dict = {}


def thermal_well_shells(
    model, temperature: float, *, top_widths: float = 12.0, grid: int = 1201, n_energies: int = 4001
) -> WellShells:
    """thermal_well_shells(model, T, top_widths=12, grid=1201, n_energies=4001) -> WellShells: the energy shells of
    ``model``'s well up to E_b + ``top_widths`` T (E_b the lowest saddle's energy, T the temperature in energy
    units), by :func:`well_shells`, computed once per system, temperature and settings and kept for later calls.

    The shells depend on the potential only; every rate of :func:`well_energy_diffusion` at that temperature
    (any γ) reads the same ones. Above E_b + top_widths T the population is e^{−top_widths} of the barrier's.
    The system is known by its potential expression and parameters (``model.potential_text``, ``model.params``).

    Examples
    --------
    Hénon–Heiles at T = 1/18 (ΔE/T = 3): the shells reach E_b + 3T = 1/3, and a second call returns the same
    object:

    >>> from hhscatter.model import HenonHeiles
    >>> sh = thermal_well_shells(HenonHeiles(), 1 / 18, top_widths=3.0, grid=301, n_energies=201)
    >>> round(sh.top, 12), round(sh.barrier, 12)
    (0.333333333333, 0.166666666667)
    >>> thermal_well_shells(HenonHeiles(), 1 / 18, top_widths=3.0, grid=301, n_energies=201) is sh
    True
    """
    check.system(model)
    temperature = check.number(temperature, "temperature", positive=True)
    top_widths = check.number(top_widths, "top_widths", positive=True)
    grid = check.count(grid, "grid", 51)
    n_energies = check.count(n_energies, "n_energies", 3)
    key = (model.potential_text, tuple(sorted(dict(model.params).items())), temperature, top_widths, grid, n_energies)
    if key not in _THERMAL_SHELLS:
        e_b = float(model.potential(np.array(0.0), np.array(0.0))) + well_barrier(model)
        _THERMAL_SHELLS[key] = well_shells(model, e_b + top_widths * temperature, grid=grid, n_energies=n_energies)
    return _THERMAL_SHELLS[key]


def is_separable(model, *, span: float = 1.0, nodes: int = 5, rtol: float = 1e-12) -> bool:
    """is_separable(model, span=1, nodes=5, rtol=1e-12) -> whether ``model``'s potential is a sum of a function
    of x and a function of y: its mixed derivative ∂²V/∂x∂y vanishes on a ``nodes`` × ``nodes`` lattice of
    [−span, span]² (``span`` in length units; the exact second derivatives of :func:`hessian`).

    A decision, not a sample, for a polynomial potential of degree ≤ ``nodes`` + 1: its mixed derivative is then
    a polynomial of degree ≤ ``nodes`` − 1 in each variable, which is zero everywhere when it is zero on the
    lattice. For other potentials it is a necessary condition. Zero means |V_xy| ≤ ``rtol`` times the largest
    |V_xx|, |V_yy| on the lattice (or 1). When V is separable, each degree of freedom keeps its own energy between
    kicks: no orbit explores its whole energy shell (the ergodicity the shells' energy-diffusion theory assumes).

    Examples
    --------
    A sum of two one-dimensional wells is separable; Hénon–Heiles (V_xy = 2x) is not:

    >>> from hhscatter.model import HenonHeiles, make_system
    >>> is_separable(make_system(potential="(x**2 + y**2)/2 - x**3/3 - 5*y**3/18"))
    True
    >>> is_separable(HenonHeiles())
    False
    """
    check.system(model)
    span = check.number(span, "span", positive=True)
    nodes = check.count(nodes, "nodes", 2)
    rtol = check.number(rtol, "rtol", minimum=0.0)
    # distinct nodes (Chebyshev's, turned off the axes so that none is 0)
    xs = span * np.cos(np.pi * (np.arange(nodes) + 0.5) / nodes + 0.1)
    h = np.array([hessian(model, float(x), float(y)) for x in xs for y in xs])
    if not np.all(np.isfinite(h)):
        raise ConfigError(f"the potential's second derivatives are not finite on [−{span:g}, {span:g}]²: set span")
    scale = max(1.0, float(np.max(np.abs(h[:, 0, 0]))), float(np.max(np.abs(h[:, 1, 1]))))
    return bool(np.all(np.abs(h[:, 0, 1]) <= rtol * scale))
