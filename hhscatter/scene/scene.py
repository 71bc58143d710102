"""Scenes: what one simulation computes, as a frozen, validated dataclass.

A scene is loaded from ``studies/<name>/scene.toml`` (table ``[scene]``, and
optionally ``[sections]``, ``[snapshots]`` and ``[scale.<name>]`` overrides)
or built from CLI flags. Every bad value is refused before any work with a
``ConfigError`` naming the parameter and its allowed range.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hhscatter._version import ENGINE_REVISION
from hhscatter.errors import ConfigError, SceneError  # noqa: F401 (SceneError: the old name of ConfigError)
from hhscatter.model import HenonHeiles, System
from hhscatter.model.spec import resolve
from hhscatter.scene.noise import KICK_FRACTION, KICK_MAX_FRACTION, KICK_SECONDS, KICKS_PER_ORBIT_MAX, Noise
from hhscatter.scene.recording import (
    SNAPSHOT_LIST_MAX,
    SNAPSHOTS_MAX,
    Follow,
    SectionWindow,
    SnapshotGrid,
    finite_number,
    plus_zero,
)

TOL_RANGE = (1e-18, 1e-6)

# Upper bounds, each with its reason (checked before any work; hhscatter.scene.scene.Scene._validate):
#: r_esc ≤ R_ESC_MAX · r_s (r_s the system's saddle distance): far out |V| ≫ E, and the energy error of the escape
#: decision grows like tol·|V|/E (cancellation between kinetic and potential energy): for a cubic |V| ≈ r³/3 at
#: E ≈ 0.2, 2e-4 at r = 1e4 already.
#: r_far ≤ R_FAR_MAX · r_s: an escaped orbit is only followed on towards its blow-up; outcomes and times are
#: checked not to change up to r_far = 1e8 (a stress benchmark), not beyond
R_ESC_MAX, R_FAR_MAX = 100.0, 1e8
#: E0 ≤ E0_MAX · E_c: far above the saddle every orbit leaves within a fraction of a period (nothing to
#: scatter), and p² = 2(E − V) overflows float64 near 1e308
E0_MAX = 1000.0
#: γ ≤ GAMMA_MAX · ω, ω the system's frequency (``model.frequency``: the square root of the largest eigenvalue of
#: V's Hessian at the well's minimum, its fastest small oscillation). With the linear drag −γp the small
#: oscillations are overdamped from γ = 2ω on; at GAMMA_MAX · ω the momentum relaxes within 1/γ, under 2 % of a
#: period 2π/ω, so a larger γ studies nothing new and only makes the equations stiff. The quadratic drag −γ|p|p
#: has the same bound on the number γ, as a guard in the system's units rather than the onset of overdamping.
GAMMA_MAX = 10.0
#: n ≤ N_MAX orbits per run: a lifetimes table of 1e9 orbits is ≈ 90 GB when read into memory; split larger
#: ensembles into several runs (other seeds)
N_MAX = 10**9
#: at most CHUNKS_MAX part files per table and run point (file-system limits, one task per chunk)
CHUNKS_MAX = 100_000
#: t_max ≤ T_MAX_MAX / ω: every orbit still inside at t_max (a trapped or censored one) is integrated all the way,
#: at a cost ∝ t_max; 2000 times the paper's 5000, where no window of the analyses reaches, and a value such as
#: 1e300 would never end
T_MAX_MAX = 1e7
#: seed ≤ SEED_MAX: it is stored (scene.json, part metadata) and read back as a 64-bit integer by other tools
SEED_MAX = 2**63 - 1
#: chunk_size ≤ CHUNK_SIZE_MAX orbits: a chunk's rows (≈ 90 B per orbit, more with sections) are held in memory
#: until its part files are written
CHUNK_SIZE_MAX = 10**7
#: a region scene's E0 must exceed E_c by more than EC_MARGIN·E_c: a sampled initial energy |p|²/2 + V is E0 only
#: up to a few units of rounding (≈ 1e-16 relative), and an orbit whose computed energy is ≤ E_c has settled
#: before it starts (the IC-table check refuses such rows, :func:`hhscatter.scene.ics.check_ics`)
EC_MARGIN = 1e-9


#: the radius field of a scene whose region is not the disk and that gives none: no region but the disk reads it,
#: and it keeps the value every scene had before the disk's default came from the system (so their hashes stay)
UNUSED_RADIUS = 0.5
#: the initial-condition regions of a scene (hhscatter.scene.ics)
REGIONS = ("disk", "well", "square")
#: the momentum conventions of region ICs (hhscatter.scene.ics): 'tangential' on the section ṙ = 0, φ̇ > 0 (the
#: authors' goodICs; the default), 'random' uniform in direction on the circle
MOMENTA = ("tangential", "random")


@dataclass(frozen=True)
class Scene:
    """One ensemble simulation: N orbits of a system with drag (Hénon–Heiles by default), Eqs. (eq:H), (eqn:hh_potential).

    Frozen and validated when made (every bound with its reason). Units are the model's natural units
    (ω = λ = 1 in the paper): energies in units of the potential, times in 1/ω. Every bound that depends on
    the system (E_c, the saddle distance r_s, the frequency ω) is read from :attr:`model`.

    Parameters
    ----------
    energy : float
        E0, the initial energy of every orbit; must exceed the system's E_c (1/6 in the paper). None only
        with ``ics`` (the table fixes the energies).
    n : int
        Number of orbits N > 0 (an integral float such as 2e4 is accepted).
    gamma : float
        Drag γ ≥ 0 (1/time) of the force −γp; γ = 0 is the conservative system.
    seed : int
        ≥ 0; with the orbit index it fixes every initial condition.
    region : {'disk', 'well', 'square'}
        'disk': uniform in area in r < radius; 'well': uniform in the well's part of {V < E_c} (the saddle triangle of
        Hénon–Heiles) where V < E;
        'square': the authors' ``goodICs``, uniform in [−r_s, r_s]² where V < E, no radius cut (orbits
        that start at r ≥ r_esc are escaped at t = 0). Momenta follow ``momentum``.
    radius : float, optional
        Disk radius R; default: the system's :meth:`~hhscatter.model.System.default_ic_radius`, half the saddle
        distance r_s (0.5 for Hénon–Heiles with ω = λ = 1, as in the authors' code). Read by the disk only (the
        other regions keep :data:`UNUSED_RADIUS` when none is given).
    r_esc : float, optional
        Escape radius, > the saddle distance r_s; default: the system's
        :meth:`~hhscatter.model.System.default_escape_radius` at E0 (1.5 for Hénon–Heiles: beyond the
        Lyapunov orbits of every exit up to E = 0.5, study ``resc``; the paper's 1.03 lets 0.3–2 % of
        'escaped' orbits return at E = 0.25–0.35).
    r_far : float, optional
        Dissipative runs: radius beyond which an escaped orbit is stopped (default max(10 r_s, 2 r_esc)).
    t_max : float
        Maximum orbit time (default 5000, at most :data:`T_MAX_MAX`/ω); orbits alive then are censored.
    tol : float
        Taylor integrator tolerance in [1e-18, 1e-6] (default 1e-15).
    omega, lam : float
        Hénon–Heiles' parameters ω, λ > 0 (default 1, 1); with a ``system`` they stay at 1 and are not written
        (:meth:`to_dict`).
    system : dict or System, optional
        The system as data (:mod:`hhscatter.model.spec`): a built-in by ``name`` or a ``potential`` in x, y,
        with ``params`` and ``dissipation``; None is Hénon–Heiles(ω, λ) with linear drag (left out of the
        scene's hash, as are Hénon–Heiles specs with linear drag, which become ω and λ).
    chunk_size : int
        Orbits per part file (default 10000); the tables do not depend on it (bitwise).
    batch_size : int, optional
        SIMD lanes (default: heyoka's recommended size); no effect on results.
    ics : str, optional
        Path of a Parquet/CSV table of initial states with columns x, y, px, py [, traj_id]; a relative path is
        made absolute against the working directory (a scene file's own ``ics`` against the file's folder,
        :func:`~hhscatter.scene.schema.load_scene`), so that ``scene.json`` names one file.
    sections : SectionWindow, optional
        Which crossings of the section ṙ = 0, φ̇ > 0 to record (default: no sections table).
    snapshots : tuple of float, optional
        Orbit times at which the energy of every live orbit is recorded.
    follow : Follow, optional
        Conservative runs: escaped orbits followed to r_far (table ``crossings``).
    continue_settled : bool
        Dissipative scenes with snapshots: settled orbits go on past E_c to the last snapshot time, and
        their energies there are snapshot rows after t_end (for ⟨E⟩(t), paper Fig. 3).
    momentum : {'tangential', 'random'}
        Direction of the initial momentum of region ICs, |p| = √(2(E0 − V)) in both: 'tangential' (default)
        on the section ṙ = 0, φ̇ > 0 (the authors' ``goodICs``); 'random' uniform on the circle, drawn per
        orbit from the seed (not on the section: its first recorded crossing is its first ṙ = 0 root with
        φ̇ > 0 at t > 0). The same for every region; not with ``ics`` (the table fixes the momenta).
    noise : Noise, optional
        Random forces on the momenta (:class:`Noise`): a heat bath of temperature T with drag, a noise of
        strength σ without. Such a scene records lifetimes only; escape is the first outward r_esc crossing
        (settling below E_c is not an outcome: the noise lifts the orbit again), censoring at t_max.
    tangent : bool
        Integrate the tangent dynamics with each orbit (default false): a tangent vector δq and its
        log-stretch Λ (:func:`hhscatter.integrate.events.tangent_equations`; δq(0) orthogonal to ∇H and to the
        Hamiltonian flow, :func:`hhscatter.integrate.events.tangent_start`). The lifetimes table gains the
        column ``log_stretch``, Λ at t_end (the finite-time Lyapunov exponent is Λ/t_end). Events, outcome
        rules, steps and so every orbit are those of the scene without it, bit for bit (δq, carried at a tiny
        norm, never sets a step: :data:`hhscatter.integrate.events.TANGENT_NORM`; Λ ≤ 600: orbits beyond
        it are counted and warned of, :data:`hhscatter.integrate.events.MAX_LOG_STRETCH`). Not with
        snapshots, noise or a section window that opens after t = 0.
    name : str
        A label for progress lines and the tables' metadata.

    Raises
    ------
    ConfigError
        A value out of range, with the key and the reason (before any work).

    Examples
    --------
    >>> import hhscatter
    >>> scene = hhscatter.Scene(energy=0.3, n=2e4, gamma=0.01, seed=1)
    >>> scene.n, round(scene.model.critical_energy, 12)
    (20000, 0.166666666667)
    >>> hhscatter.Scene(energy=0.1, n=10)
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: energy must be > E_c = 0.1666666667 in a conservative escape scene (no escape is possible below it), got 0.1
    """

    energy: float | None
    n: int
    gamma: float = 0.0
    seed: int = 0
    region: str = "disk"
    radius: float | None = None
    r_esc: float | None = None
    r_far: float | None = None
    t_max: float = 5000.0
    tol: float = 1e-15
    omega: float = 1.0
    lam: float = 1.0
    chunk_size: int = 10000
    batch_size: int | None = None
    ics: str | None = None
    sections: SectionWindow | None = None
    snapshots: tuple | None = None
    follow: Follow | None = None
    continue_settled: bool = False
    momentum: str = "tangential"
    noise: Noise | None = None
    tangent: bool = False
    system: dict | None = field(default=None, hash=False)
    name: str = "scene"
    _model: System = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        for name in ("n", "seed", "chunk_size"):  # counts written as floats (n=2e4), like the CLI's -n 2e4
            v = getattr(self, name)
            if isinstance(v, (float, np.floating)) and math.isfinite(v) and v == int(v):
                object.__setattr__(self, name, int(v))
        object.__setattr__(self, "_model", self._make_model())
        object.__setattr__(self, "gamma", plus_zero(self.gamma))
        if self.radius is None:  # the disk's is the system's; the other regions have none (see UNUSED_RADIUS)
            radius = self._model.default_ic_radius() if self.region == "disk" else UNUSED_RADIUS
            object.__setattr__(self, "radius", float(radius))
        if self.r_esc is None:
            e = None if self.energy is None or isinstance(self.energy, bool) else finite_number("energy", self.energy)
            object.__setattr__(self, "r_esc", float(self._model.default_escape_radius(e)))
        self._validate()

    def _make_model(self) -> System:
        """The system: Hénon–Heiles(ω, λ), or the ``system`` spec (normalised: a Hénon–Heiles spec with linear
        drag becomes ω and λ, so that it has the hash of the same scene written without a [system] table)."""
        if self.system is None:
            try:
                return HenonHeiles(finite_number("omega", self.omega), finite_number("lam", self.lam))
            except ValueError as exc:
                raise ConfigError(str(exc)) from None
        if (self.omega, self.lam) != (1.0, 1.0):
            raise ConfigError(
                "omega and lam are Hénon–Heiles' scene keys: with a system give them in its params "
                "(system.params.omega, system.params.lam)"
            )
        model, spec = resolve(self.system)
        if isinstance(model, HenonHeiles) and model.hash_items() is None:
            object.__setattr__(self, "omega", model.omega)
            object.__setattr__(self, "lam", model.lam)
            spec = None
        object.__setattr__(self, "system", spec)
        return model

    @property
    def model(self) -> System:
        """The system (:class:`hhscatter.model.System`): potential, drag law, E_c, exits, Ω."""
        return self._model

    @property
    def dissipative(self) -> bool:
        return self.gamma > 0

    @property
    def noise_strength(self) -> float:
        """σ of dp = … + σ dW (momentum/√time): √(2γT) for a heat bath, the given σ without drag, 0 without noise."""
        if self.noise is None:
            return 0.0
        if self.noise.temperature is not None:
            return math.sqrt(2.0 * self.gamma * self.noise.temperature)
        return self.noise.sigma

    @property
    def kick_interval(self) -> float | None:
        """The noise's kick interval h (time units): the given one or KICK_FRACTION · min(1/ω, 1/γ); None without
        noise. (The engine uses t_max/⌈t_max/h⌉ ≤ h.)"""
        if self.noise is None:
            return None
        if self.noise.kick is not None:
            return self.noise.kick
        return KICK_FRACTION * self._shortest_time()

    def _shortest_time(self) -> float:
        """min(1/ω, 1/γ) (time units): the time scale a kick interval must resolve."""
        rate = max(self.model.frequency, self.gamma)
        return 1.0 / rate

    # -- validation ---------------------------------------------------------
    def _validate(self):
        """Every field in range, checked in this order (the first bad one is the error); snapshots normalised."""
        gamma, t_max = self._check_dynamics()
        r_esc = self._check_radii()
        self._check_chunks()
        self._check_energy(gamma)
        self._check_recording(gamma, t_max, r_esc)
        self._check_noise(gamma, t_max)
        self._check_tangent()

    def _check_tangent(self):
        """tangent: a bool, on the stream scheduler's scenes (no snapshots, no noise, no late section window)."""
        if not isinstance(self.tangent, bool):
            raise ConfigError(f"tangent must be true or false, got {self.tangent!r}")
        if not self.tangent:
            return
        for name, given in (
            ("snapshots", bool(self.snapshots)),
            ("noise", self.noise is not None),
            ("sections.t_from > 0", self.sections is not None and self.sections.t_from > 0),
        ):
            if given:
                raise ConfigError(
                    f"tangent = true is not available with {name}: the tangent dynamics run in scenes without "
                    "snapshots or noise whose section window (if any) opens at t = 0"
                )

    def _check_noise(self, gamma, t_max):
        """noise: a heat bath needs linear drag, a noise strength none; the kick interval's bound; a noise scene
        records lifetimes only."""
        if self.noise is None:
            return
        if not isinstance(self.noise, Noise):
            raise ConfigError("noise must be a Noise or None")
        if self.noise.temperature is not None:
            if not gamma > 0:
                raise ConfigError(
                    "noise.temperature is a heat bath: it needs drag gamma > 0 (without drag give noise.sigma)"
                )
            if self.model.dissipation != "linear":
                raise ConfigError(
                    f"noise.temperature needs the linear drag law (the heat bath's fluctuation–dissipation pair), "
                    f"got system.dissipation = {self.model.dissipation!r}"
                )
        elif gamma > 0:
            raise ConfigError(
                f"noise.sigma is noise without drag (gamma = 0), got gamma = {gamma:g}: with drag give "
                "noise.temperature (a heat bath)"
            )
        h_max = KICK_MAX_FRACTION * self._shortest_time()
        if self.noise.kick is not None and self.noise.kick > h_max:
            raise ConfigError(
                f"noise.kick must be ≤ {KICK_MAX_FRACTION:g} min(1/ω, 1/γ) = {h_max:g}, got {self.noise.kick:g} "
                "(the splitting would resolve neither the oscillation nor the drag)"
            )
        kicks = t_max / self.kick_interval  # (inf for a kick of 1e-300)
        if kicks > KICKS_PER_ORBIT_MAX:
            what = "noise.kick" if self.noise.kick is not None else "t_max"
            cost = self.n * kicks * KICK_SECONDS / 3600.0
            h = "noise.kick" if self.noise.kick is not None else f"the kick interval {KICK_FRACTION:g} min(1/ω, 1/γ)"
            raise ConfigError(
                f"{what}: t_max / {h} = {t_max:g} / {self.kick_interval:.3g} = {kicks:.3g} kicks per orbit, "
                f"more than {KICKS_PER_ORBIT_MAX:.0e} (the {self.n} orbits would take ≈ {cost:.3g} CPU-hours at "
                f"≈ {KICK_SECONDS * 1e6:g} µs a kick): give a larger noise.kick or a shorter t_max"
            )
        for name, given in (
            ("sections", self.sections is not None),
            ("snapshots", bool(self.snapshots)),
            ("follow", self.follow is not None),
            ("continue_settled", self.continue_settled),
        ):
            if given:
                raise ConfigError(f"{name} is not available with noise: a noise scene records lifetimes only")
        if self.r_far is not None:
            raise ConfigError("r_far is not read with noise: the escape is the first outward r_esc crossing")

    def _check_dynamics(self):
        """γ, n, seed, tol and t_max; returns (γ, t_max)."""
        m = self.model
        gamma = finite_number("gamma", self.gamma)
        if gamma < 0:
            raise ConfigError(f"gamma must be ≥ 0 (γ = 0 is conservative), got {gamma}")
        if gamma > GAMMA_MAX * m.frequency:
            raise ConfigError(
                f"gamma must be ≤ {GAMMA_MAX:g} ω = {GAMMA_MAX * m.frequency:g} (ω the system's frequency), got "
                f"{gamma:g} (with the linear drag the motion is overdamped from γ = 2 ω on; above the bound orbits "
                "settle within a fraction of a period)"
            )
        if not isinstance(self.n, (int, np.integer)) or isinstance(self.n, bool) or self.n <= 0:
            raise ConfigError(f"n (number of orbits) must be an integer > 0, got {self.n!r}")
        if self.n > N_MAX:
            raise ConfigError(
                f"n must be ≤ {N_MAX:.0e} per run, got {self.n:.3g} (its lifetimes table alone would "
                "need ≈ 90 bytes per orbit in memory when read): split it into runs with other seeds"
            )
        if not isinstance(self.seed, (int, np.integer)) or isinstance(self.seed, bool) or self.seed < 0:
            raise ConfigError(f"seed must be an integer ≥ 0, got {self.seed!r}")
        if self.seed > SEED_MAX:
            raise ConfigError(
                f"seed must be ≤ 2**63 − 1 = {SEED_MAX}, got {self.seed} (it is stored and read back as a "
                "64-bit integer)"
            )
        tol = finite_number("tol", self.tol)
        if not TOL_RANGE[0] <= tol <= TOL_RANGE[1]:
            raise ConfigError(f"tol must be in [{TOL_RANGE[0]:g}, {TOL_RANGE[1]:g}], got {tol:g}")
        t_max = finite_number("t_max", self.t_max)
        if t_max <= 0:
            raise ConfigError(f"t_max must be > 0, got {t_max}")
        if t_max > T_MAX_MAX / m.frequency:
            raise ConfigError(
                f"t_max must be ≤ {T_MAX_MAX:g}/ω = {T_MAX_MAX / m.frequency:g}, got {t_max:g} (every orbit "
                "still inside at t_max is integrated all the way, at a cost ∝ t_max)"
            )
        return gamma, t_max

    def _check_radii(self):
        """r_esc, r_far, the IC region and its radius; returns r_esc."""
        m = self.model
        r_esc = finite_number("r_esc", self.r_esc)
        if r_esc <= m.saddle_radius:
            raise ConfigError(
                f"r_esc must be > the saddle distance r_s = {m.saddle_radius:g} "
                f"(outside the Lyapunov orbits), got {r_esc}"
            )
        if r_esc > R_ESC_MAX * m.saddle_radius:
            raise ConfigError(
                f"r_esc must be ≤ {R_ESC_MAX:g} r_s = {R_ESC_MAX * m.saddle_radius:g}, got {r_esc:g} "
                "(energy conservation: far out |V| ≫ E and the energy error grows like tol·|V|/E)"
            )
        if self.r_far is not None and finite_number("r_far", self.r_far) <= r_esc:
            raise ConfigError(f"r_far must be > r_esc = {r_esc}, got {self.r_far}")
        if self.r_far is not None and self.r_far > R_FAR_MAX * m.saddle_radius:
            raise ConfigError(
                f"r_far must be ≤ {R_FAR_MAX:g} r_s = {R_FAR_MAX * m.saddle_radius:g}, got "
                f"{self.r_far:g} (the range checked by the stress study; V heads for float64 "
                "overflow beyond)"
            )
        if self.region not in REGIONS:
            raise ConfigError(f"region must be one of {REGIONS}, got {self.region!r}")
        # where orbits move: inside r_esc, escaped ones followed to r_far (drag, follow), square ICs in [−r_s, r_s]²
        what, reach = "r_esc", r_esc
        if self.gamma > 0 or self.follow is not None:
            what, reach = "r_far", self.r_far if self.r_far is not None else max(10.0 * m.saddle_radius, 2.0 * r_esc)
        if self.region == "square" and math.sqrt(2.0) * m.saddle_radius > reach:
            what, reach = "the square region", math.sqrt(2.0) * m.saddle_radius
        bad = m.nonfinite_point(reach)
        if bad is not None:
            raise ConfigError(
                f"system.potential: V or its gradient is not finite at ({bad[0]:.6g}, {bad[1]:.6g}), "
                f"inside r ≤ {reach:g} ({what}) where orbits move; give a potential that is finite "
                f"and real there, or a smaller {what}"
            )
        if not isinstance(self.momentum, str) or self.momentum not in MOMENTA:
            raise ConfigError(f"momentum must be one of {MOMENTA}, got {self.momentum!r}")
        radius = finite_number("radius", self.radius)
        if radius <= 0:
            raise ConfigError(f"radius must be > 0, got {radius}")
        if radius > r_esc:
            raise ConfigError(
                f"radius must be ≤ r_esc = {r_esc:g}, got {radius:g} (a disk point beyond r_esc has "
                "escaped already, and the sampler would reject almost every draw: V < E only "
                "holds near the well)"
            )
        return r_esc

    def _check_chunks(self):
        """chunk_size (and the number of part files it makes) and batch_size."""
        if (
            not isinstance(self.chunk_size, (int, np.integer))
            or isinstance(self.chunk_size, bool)
            or self.chunk_size <= 0
        ):
            raise ConfigError(f"chunk_size must be an integer > 0, got {self.chunk_size!r}")
        if self.chunk_size > CHUNK_SIZE_MAX:
            raise ConfigError(
                f"chunk_size must be ≤ {CHUNK_SIZE_MAX:.0e}, got {self.chunk_size:.3g} (a chunk's rows are "
                "held in memory until its part files are written)"
            )
        if -(-self.n // self.chunk_size) > CHUNKS_MAX:
            raise ConfigError(
                f"chunk_size {self.chunk_size} gives {-(-self.n // self.chunk_size)} chunks for "
                f"n = {self.n}, more than {CHUNKS_MAX} part files per table: use a larger chunk_size"
            )
        if self.batch_size is not None and (
            not isinstance(self.batch_size, (int, np.integer)) or not 1 <= self.batch_size <= 64
        ):
            raise ConfigError(f"batch_size must be an integer in [1, 64], got {self.batch_size!r}")

    def _check_energy(self, gamma):
        """E0 against the region's minimum of V, E_c and its upper bound (or ics without energy)."""
        m = self.model
        if self.ics is None:
            if self.energy is None:
                raise ConfigError("energy is required unless initial conditions come from a table (ics)")
            energy = finite_number("energy", self.energy)
            # the region's minimum of V is V(0, 0) = 0 (the origin is in every region)
            if energy <= 0:
                raise ConfigError(
                    f"energy must be > 0 = min V over the {self.region!r} region "
                    f"(no point of the region is accessible), got {energy}"
                )
            if energy > E0_MAX * m.critical_energy:
                raise ConfigError(
                    f"energy must be ≤ {E0_MAX:g} E_c = {E0_MAX * m.critical_energy:.6g}, got "
                    f"{energy:g} (far above the saddles every orbit leaves at once; p² overflows "
                    "near 1e308)"
                )
            if energy <= m.critical_energy and self.noise is None:  # noise lifts an orbit over the saddles
                what = "dissipative" if gamma > 0 else "conservative escape"
                raise ConfigError(
                    f"energy must be > E_c = {m.critical_energy:.10g} in a {what} scene "
                    f"(no escape is possible below it), got {energy}"
                )
            if self.noise is None and energy - m.critical_energy <= EC_MARGIN * m.critical_energy:
                raise ConfigError(
                    f"energy must exceed E_c = {m.critical_energy!r} by more than {EC_MARGIN:g} E_c, got {energy!r} "
                    f"(E0 − E_c = {energy - m.critical_energy:.3g}): a sampled initial energy |p|²/2 + V equals E0 "
                    "only up to rounding, and an orbit that starts at or below E_c has settled before it starts"
                )
            if isinstance(self.sections, SectionWindow) and self.sections.e_min > energy:
                raise ConfigError(
                    f"sections.e_min = {self.sections.e_min:g} is above E0 = {energy:g}: the energy "
                    "never rises above E0, so no crossing would be recorded"
                )
            if isinstance(self.sections, SectionWindow) and self.noise is None:  # (noise records no sections)
                if gamma == 0 and self.sections.e_max < energy:
                    raise ConfigError(
                        f"sections.e_max = {self.sections.e_max:g} is below E0 = {energy:g}: without drag the "
                        "energy stays E0, so no crossing would be recorded"
                    )
                if gamma > 0 and self.sections.e_max < m.critical_energy and not self.continue_settled:
                    raise ConfigError(
                        f"sections.e_max = {self.sections.e_max:g} is below E_c = {m.critical_energy:.10g}: an "
                        "orbit settles (and ends) when its energy falls to E_c, so no crossing would be recorded"
                    )
        elif not isinstance(self.ics, (str, Path)) or not str(self.ics).strip():
            raise ConfigError(f"ics must be the path of a Parquet/CSV table, got {self.ics!r}")
        elif not os.path.isabs(self.ics):  # one meaning wherever the scene is read again (scene.json, --resume)
            object.__setattr__(self, "ics", os.path.abspath(self.ics))
        elif self.energy is not None:
            raise ConfigError("energy must not be given with ics: each orbit's energy comes from its table row")
        elif self.momentum != "tangential":
            raise ConfigError(
                f"momentum = {self.momentum!r} is an option of region ICs and must not be given with "
                "ics: each orbit's momentum comes from its table row"
            )

    def _check_recording(self, gamma, t_max, r_esc):
        """sections, snapshots (normalised to a sorted tuple), follow and continue_settled."""
        m = self.model
        if self.sections is not None and not isinstance(self.sections, SectionWindow):
            raise ConfigError("sections must be a SectionWindow or None")
        if self.sections is not None and self.sections.t_from >= t_max:
            raise ConfigError(
                f"sections.t_from = {self.sections.t_from:g} is not before t_max = {t_max:g}: every orbit ends by "
                "t_max, so no crossing would be recorded"
            )
        if self.snapshots is not None:
            if not isinstance(self.snapshots, SnapshotGrid) and len(self.snapshots) > SNAPSHOTS_MAX:
                raise ConfigError(
                    f"snapshots: {len(self.snapshots)} times, more than {SNAPSHOTS_MAX} (every live "
                    "orbit writes one row per time; a chunk holds them in memory)"
                )
            snaps = (
                self.snapshots if isinstance(self.snapshots, SnapshotGrid) else tuple(float(s) for s in self.snapshots)
            )
            if not snaps:
                raise ConfigError("snapshots must be a non-empty list of times or omitted")
            if not all(math.isfinite(s) and 0 <= s <= t_max for s in snaps):
                raise ConfigError(f"snapshots times must be finite and in [0, t_max = {t_max}]")
            if any(b <= a for a, b in zip(snaps, snaps[1:])):
                raise ConfigError("snapshots times must be strictly increasing")
            object.__setattr__(self, "snapshots", snaps)

        if self.follow is not None:
            if not isinstance(self.follow, Follow):
                raise ConfigError("follow must be a Follow or None")
            if gamma > 0:
                raise ConfigError(
                    "follow is for conservative scenes (gamma = 0): dissipative escapes "
                    "are already final (the orbit is followed to E_c or r_far)"
                )
            rf = self.r_far if self.r_far is not None else max(10.0 * m.saddle_radius, 2.0 * r_esc)
            if max(self.follow.radii) >= rf:
                raise ConfigError(f"follow.radii must all be < r_far = {rf:g}, got {max(self.follow.radii):g}")
        if not isinstance(self.continue_settled, bool):
            raise ConfigError(f"continue_settled must be true or false, got {self.continue_settled!r}")
        if self.continue_settled and not (gamma > 0 and self.snapshots):
            raise ConfigError(
                "continue_settled needs a dissipative scene (gamma > 0) with snapshots: "
                "it records settled orbits' energies after settling"
            )

    # -- identity -----------------------------------------------------------
    def to_dict(self) -> dict:
        """to_dict() -> plain dict; options at their defaults that older scenes did not have are left
        out, so every existing scene keeps its result_hash (and its runs on disk resume)."""
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.init}
        d["sections"] = dataclasses.asdict(self.sections) if self.sections else None
        if d["sections"] is not None and not d["sections"]["stop"]:
            del d["sections"]["stop"]
        d["snapshots"] = list(self.snapshots) if self.snapshots else None
        if isinstance(self.snapshots, SnapshotGrid) and len(self.snapshots) > SNAPSHOT_LIST_MAX:
            d["snapshots"] = dict(self.snapshots.definition)  # small metadata (see SNAPSHOT_LIST_MAX)
        if self.follow is None:
            del d["follow"]
        else:
            d["follow"] = {"radii": list(self.follow.radii)}
        if not self.continue_settled:
            del d["continue_settled"]
        if self.noise is None:  # no noise, the default: left out of the hash, so older scenes keep theirs
            del d["noise"]
        else:
            d["noise"] = {k: v for k, v in dataclasses.asdict(self.noise).items() if v is not None}
        if self.momentum == "tangential":  # the default: left out of the hash, so older scenes keep theirs
            del d["momentum"]
        if not self.tangent:  # the default: left out of the hash, so older scenes keep theirs
            del d["tangent"]
        if self.system is None:  # Hénon–Heiles with linear drag, the default: left out of the hash
            del d["system"]
        else:  # ω and λ are Hénon–Heiles' keys: a system carries its own parameters
            d["system"] = dict(self.system, params=dict(self.system["params"]))
            del d["omega"], d["lam"]
        return d

    def to_json(self) -> str:
        """Strict JSON (infinities written as the strings "inf"/"-inf")."""
        return json.dumps(_clean(self.to_dict()), sort_keys=True, allow_nan=False, default=_json_default)

    def result_hash(self) -> str:
        """sha256 of everything that determines the tables (not name, batch size): the scene and, from revision 2
        on, the engine's revision (:data:`hhscatter._version.ENGINE_REVISION`)."""
        d = self.to_dict()
        for k in ("name", "batch_size"):
            d.pop(k)
        if self.system is not None:  # hashed as before ω and λ left a system's scene.json: hashes kept
            d.update(omega=1.0, lam=1.0)
        if self.ics is not None:
            d["ics"] = file_sha256(self.ics)
        if ENGINE_REVISION > 1:  # another engine's run is another result (revision 1: hashes as before)
            d["engine_revision"] = ENGINE_REVISION
        return hashlib.sha256(json.dumps(_clean(d), sort_keys=True, default=_json_default).encode()).hexdigest()

    def replace(self, **changes: Any) -> Scene:
        return dataclasses.replace(self, **changes)


def file_sha256(path) -> str:
    """file_sha256(path) -> sha256 hex digest of a file, computed once per (path, size, mtime) per process.

    The IC table's hash is part of a scene's ``result_hash``; the cache keeps it at one read of the table
    per run, however many chunks ask for it (a changed file has another size or mtime and is hashed anew).
    """
    st = Path(path).stat()
    return _file_sha256(str(Path(path).resolve()), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=64)
def _file_sha256(path: str, size: int, mtime_ns: int) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 22), b""):
            h.update(block)
    return h.hexdigest()


def _clean(v):
    if isinstance(v, dict):
        return {k: _clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_clean(x) for x in v]
    if isinstance(v, float) and math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return v


def _json_default(v):
    if isinstance(v, float) and math.isinf(v):
        return "inf" if v > 0 else "-inf"
    if isinstance(v, np.generic):
        return v.item()
    raise TypeError(f"not JSON serialisable: {v!r}")


def _inf(v):
    if isinstance(v, str) and v.lower() in ("inf", "+inf", "-inf"):
        return float(v)
    return v


def scene_from_dict(d: dict) -> Scene:
    """scene_from_dict(d) -> Scene; inverse of ``Scene.to_dict``; unknown keys are refused."""
    d = dict(d)
    sec = d.pop("sections", None)
    if sec is not None:
        if not isinstance(sec, dict):
            raise ConfigError("sections must be a table")
        unknown = set(sec) - {f.name for f in dataclasses.fields(SectionWindow)}
        if unknown:
            raise ConfigError(f"unknown sections keys: {sorted(unknown)}")
        d["sections"] = SectionWindow(**{k: _inf(v) for k, v in sec.items()})
    fol = d.pop("follow", None)
    if isinstance(fol, Follow):
        d["follow"] = fol
    elif fol is not None:
        if not isinstance(fol, dict):
            raise ConfigError("follow must be a table with key 'radii'")
        unknown = set(fol) - {"radii"}
        if unknown:
            raise ConfigError(f"unknown follow keys: {sorted(unknown)}; allowed: ['radii']")
        d["follow"] = Follow(**fol)
    noise = d.pop("noise", None)
    if isinstance(noise, Noise):
        d["noise"] = noise
    elif noise is not None:
        if not isinstance(noise, dict):
            raise ConfigError("noise must be a table with temperature or sigma (and kick)")
        unknown = set(noise) - {f.name for f in dataclasses.fields(Noise)}
        if unknown:
            raise ConfigError(
                f"unknown noise keys: {sorted(unknown)}; allowed: ['flow', 'kick', 'sigma', 'temperature']"
            )
        d["noise"] = Noise(**noise)
    snaps = d.pop("snapshots", None)
    if isinstance(snaps, dict):
        unknown = set(snaps) - {"times", "start", "stop", "step"}
        if unknown:
            raise ConfigError(f"unknown snapshots keys: {sorted(unknown)}")
        if "times" in snaps:
            snaps = snaps["times"]
        else:
            try:
                start, stop, step = (snaps[k] for k in ("start", "stop", "step"))
            except KeyError as exc:
                raise ConfigError(f"snapshots needs 'times' or start/stop/step (missing {exc})") from None
            snaps = SnapshotGrid(start, stop, step)
    if snaps is not None:
        d["snapshots"] = snaps if isinstance(snaps, SnapshotGrid) else tuple(snaps)
    known = {f.name for f in dataclasses.fields(Scene) if f.init}
    unknown = set(d) - known
    if unknown:
        raise ConfigError(f"unknown scene keys: {sorted(unknown)}; allowed: {sorted(known)}")
    if "n" not in d:
        raise ConfigError("a scene needs 'n' (number of orbits)")
    d.setdefault("energy", None)
    return Scene(**d)
