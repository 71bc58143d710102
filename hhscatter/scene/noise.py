"""Random forces on the momenta of a scene, as data (:class:`Noise`): a heat bath of temperature T with drag, a
noise of strength σ without, and the kick interval of the splitting that integrates them
(:mod:`hhscatter.integrate.noise`). Temperatures in energy units (k_B = 1), σ in momentum/√time, times in time
units.
"""

from __future__ import annotations

from dataclasses import dataclass

from hhscatter.errors import ConfigError
from hhscatter.scene.recording import finite_number

__all__ = ["FLOWS", "KICKS_PER_ORBIT_MAX", "KICK_FRACTION", "KICK_MAX_FRACTION", "KICK_SECONDS", "Noise"]


#: the Hamiltonian flows between the kicks (the first is the default)
FLOWS = ("taylor", "symplectic")
#: the default kick interval of noise scenes, as a fraction of the shortest time scale min(1/ω, 1/γ)
#: (:class:`Noise`; the escape rate's measured bias at this interval, ≤ 1 % with either flow, is stated there)
KICK_FRACTION = 0.1
#: a kick interval above KICK_MAX_FRACTION · min(1/ω, 1/γ) is refused: the splitting resolves neither the
#: oscillation nor the drag any more (the escape rate's weak error grows like h²)
KICK_MAX_FRACTION = 0.5
#: at most KICKS_PER_ORBIT_MAX kicks per orbit, ⌈t_max / h⌉: a scene asking for more is refused, with what it
#: would cost (the default h = 0.1 min(1/ω, 1/γ) reaches it at t_max = 10⁶ min(1/ω, 1/γ))
KICKS_PER_ORBIT_MAX = 10**7
#: the cost of one kick of one orbit (seconds of one core): the Hamiltonian flow over h and the Ornstein–Uhlenbeck
#: step, measured on Hénon–Heiles (γ = 1, h = 0.1: 10⁶ orbit-kicks in 5.7 s of one core, compilation included)
KICK_SECONDS = 5e-6


@dataclass(frozen=True)
class Noise:
    """Noise(temperature=None, sigma=None, kick=None, flow=None): random forces on the momenta of a scene, as data.

    With drag (γ > 0) the noise is a heat bath at ``temperature`` T (energy units, k_B = 1), the
    fluctuation–dissipation pair of the linear drag:

        dq = p dt,   dp = −∇V dt − γ p dt + √(2γT) dW;

    without drag (γ = 0) it is a noise of ``strength`` σ alone (energy diffuses, nothing settles):

        dq = p dt,   dp = −∇V dt + σ dW,

    with W a two-dimensional Wiener process (one per orbit). Exactly one of ``temperature`` (γ > 0) and
    ``sigma`` (γ = 0) is given.

    Integration (:mod:`hhscatter.integrate.noise`): Strang splitting O(h/2) · Φ_H(h) · O(h/2) with Φ_H the
    Hamiltonian flow on heyoka's Taylor integrator (events at their exact roots: positions are continuous, so
    no crossing of r_esc is missed between kicks) and O the exact Ornstein–Uhlenbeck step on the momenta,
    p ← e^{−γδ} p + √(T(1 − e^{−2γδ})) ξ (σ√δ ξ without drag), δ = h/2. Both parts preserve the Boltzmann
    density e^{−H/T} exactly, so the invariant measure carries no splitting error at any h; dynamical
    quantities (escape rates) carry a weak error O(h²). Measured (``make bench``, ``benchmarks/noise_rate.py``:
    Hénon–Heiles, γ = 1, ΔE/T = 3, the rate on [20, 150] against a compiled BAOAB at dt = 0.02 with 480 000
    orbits): the rate's bias is +1.4 % ± 0.4 % at h = 0.5, +0.6 % ± 0.7 % at h = 0.2 and −1.8 % ± 1.5 % at
    the default h = 0.1 (the h² law from h = 0.5 gives ≈ +0.1 % there); with ``flow = "symplectic"`` +3.7 % ±
    0.4 % at h = 0.5, +1.0 % ± 0.4 % at h = 0.25, +0.4 % ± 0.3 % at h = 0.2 and +0.3 % ± 0.3 % at the default
    h = 0.1 (≈ 15 h² %).

    Parameters
    ----------
    temperature : float, optional
        Heat-bath temperature T > 0 (energy units); needs γ > 0 and the linear drag law.
    sigma : float, optional
        Noise strength σ > 0 (momentum / √time); needs γ = 0.
    kick : float, optional
        Kick interval h (time units), 0 < h ≤ KICK_MAX_FRACTION · min(1/ω, 1/γ); default KICK_FRACTION ·
        min(1/ω, 1/γ). The engine uses h' = t_max / ⌈t_max/h⌉ ≤ h, so t_max falls on a kick. A scene refuses
        more than KICKS_PER_ORBIT_MAX kicks per orbit (⌈t_max/h⌉), saying what they would cost.
    flow : {"taylor", "symplectic"}, optional
        The Hamiltonian flow between the kicks: ``"taylor"`` (the default, also None) heyoka's Taylor integrator
        at the scene's tolerance, events at their exact roots (:mod:`hhscatter.integrate.noise`);
        ``"symplectic"`` one compiled fourth-order symplectic step per kick with the escape at the exact root of
        its Hermite interpolant and counter-based random streams (:mod:`hhscatter.integrate.noise_symplectic`),
        ≈ 25× cheaper at the default kick (``make bench``). The two give statistically equal, not identical, tables.

    Raises
    ------
    ConfigError
        Neither or both of temperature and sigma, a value ≤ 0 or not finite, an unknown flow (naming the key).

    Examples
    --------
    >>> import hhscatter
    >>> s = hhscatter.Scene(energy=0.1, n=10, gamma=1.0, noise=hhscatter.Noise(temperature=1 / 36))
    >>> round(s.noise.temperature, 6), s.noise_strength == (2 * 1.0 / 36) ** 0.5, s.kick_interval
    (0.027778, True, 0.1)
    """

    temperature: float | None = None
    sigma: float | None = None
    kick: float | None = None
    flow: str | None = None

    def __post_init__(self):
        if self.flow is not None:
            if self.flow not in FLOWS:
                raise ConfigError(f"noise.flow must be one of {list(FLOWS)}, got {self.flow!r}")
            if self.flow == FLOWS[0]:  # the default, spelled out: the same scene (and scene hash) as without it
                object.__setattr__(self, "flow", None)
        for name in ("temperature", "sigma", "kick"):
            v = getattr(self, name)
            if v is not None:
                v = finite_number(f"noise.{name}", v)
                if not v > 0:
                    raise ConfigError(f"noise.{name} must be > 0, got {v:g}")
                object.__setattr__(self, name, v)
        if (self.temperature is None) == (self.sigma is None):
            raise ConfigError(
                "noise needs exactly one of temperature (a heat bath, with drag gamma > 0) and sigma "
                "(a noise strength, without drag)"
            )
