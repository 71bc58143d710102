"""The noise scheduler: Langevin dynamics by splitting, heyoka's exact-event flow between vectorised kicks.

A scene with ``[noise]`` (:class:`hhscatter.scene.noise.Noise`) integrates

    dq = p dt,   dp = −∇V dt − γ p dt + σ dW,     σ = √(2γT) (heat bath) or the given σ (γ = 0),

by the Strang splitting O(h/2) · Φ_H(h) · O(h/2) (the "OBABO" family with the exact Hamiltonian flow in
place of the Verlet B-A-B):

* Φ_H(h): Hamilton's equations without drag on the batch Taylor integrator, with the scene's escape event
  (:func:`hhscatter.integrate.events.scene_events`: the first outward r_esc crossing), found at its exact
  root inside the step; kicks change momenta only, so the position is continuous and no crossing is lost
  between kicks;
* O(δ): the exact Ornstein–Uhlenbeck step on the momenta, p ← c p + s ξ with c = e^{−γδ},
  s = σ √((1 − c²)/(2γ)) (= √(T(1 − c²)) for a heat bath; σ√δ for γ = 0), ξ standard normal per
  component.

Both parts leave the Boltzmann density e^{−H/T} invariant exactly (Φ_H conserves H and phase volume, O
the Maxwell distribution of p), so the stationary measure has no splitting error at any h (up to the
integrator's tolerance); the dynamics has a weak error O(h²) (Strang splitting of the generator; the
escape rate's, measured, is stated in :class:`hhscatter.scene.noise.Noise`).

Scheduling is that of the epoch scheduler (:mod:`hhscatter.integrate.epochs`) with the kick interval as
the epoch: all lanes propagate to h together (one ``propagate_until`` call), then one numpy kick acts on
every live lane at once; an orbit that escapes inside an epoch is parked at the origin (a fixed point,
never kicked) until the epoch ends, and new orbits start at epoch starts. The Python per kick is one call
and a few array operations, amortised over the batch (the default batch is :data:`NOISE_BATCH` lanes).

Random numbers: orbit ``traj_id`` of a scene with seed s draws from its own stream,
``Generator(Philox(SeedSequence(s, spawn_key=(NOISE_STREAM, traj_id))))`` (the initial conditions use
spawn keys of length one: the streams are independent); its k-th kick uses the normals 4k … 4k+3 of it
(two per half step), drawn in blocks of :data:`BLOCK` kicks. An orbit's kicks therefore depend on
(seed, traj_id, k) alone, and its time is its kick count times h plus the lane time: tables are the same,
byte for byte, whatever the workers, chunks, batch size or backend.
"""

from __future__ import annotations

import math

import numpy as np

from hhscatter.integrate.epochs import _Epochs
from hhscatter.integrate.schedulers import register

#: spawn key that marks the noise streams (initial conditions use keys of length one: (block,))
NOISE_STREAM = 0x4E4F495345  # "NOISE"
#: kicks per block of normals drawn from an orbit's stream at once (the stream is the same whatever the block)
BLOCK = 256
#: lanes of the noise scheduler (the Python per kick is shared by them; see ``make bench``)
NOISE_BATCH = 64


def kick_interval(scene) -> float:
    """kick_interval(scene) -> h' = t_max / ⌈t_max/h⌉ (time units): the scene's kick interval h, shortened so
    that t_max falls on a kick.

    Examples
    --------
    >>> import hhscatter
    >>> s = hhscatter.Scene(energy=0.1, n=1, gamma=1.0, t_max=1.05, noise=hhscatter.Noise(temperature=0.05))
    >>> round(kick_interval(s), 12)
    0.095454545455
    """
    return scene.t_max / max(1, math.ceil(scene.t_max / scene.kick_interval - 1e-12))


def ou_coefficients(gamma: float, sigma: float, delta: float) -> tuple[float, float]:
    """ou_coefficients(γ, σ, δ) -> (c, s): the exact Ornstein–Uhlenbeck step dp = −γp dt + σ dW over δ is
    p ← c p + s ξ, c = e^{−γδ}, s² = σ²(1 − c²)/(2γ) (σ²δ at γ = 0).

    Examples
    --------
    >>> c, s = ou_coefficients(1.0, (2 * 1.0 * 0.25) ** 0.5, 50.0)   # long step: p ~ N(0, T = 0.25)
    >>> round(c, 12), round(s * s, 12)
    (0.0, 0.25)
    >>> ou_coefficients(0.0, 2.0, 0.25)
    (1.0, 1.0)
    """
    if gamma == 0.0:
        return 1.0, sigma * math.sqrt(delta)
    c = math.exp(-gamma * delta)
    return c, sigma * math.sqrt(-math.expm1(-2.0 * gamma * delta) / (2.0 * gamma))


def orbit_stream(seed: int, traj_id: int) -> np.random.Generator:
    """orbit_stream(seed, traj_id) -> the Generator of orbit ``traj_id``'s kicks (module docstring).

    Examples
    --------
    >>> a = orbit_stream(1, 7).standard_normal(3)
    >>> b = orbit_stream(1, 7).standard_normal(3)
    >>> bool((a == b).all()), bool((a == orbit_stream(1, 8).standard_normal(3)).any())
    (True, False)
    """
    return np.random.Generator(
        np.random.Philox(np.random.SeedSequence(int(seed), spawn_key=(NOISE_STREAM, int(traj_id))))
    )


@register
class _Noisy(_Epochs):
    """The noise scheduler: epochs of one kick interval, a vectorised Ornstein–Uhlenbeck kick around each."""

    name = "noise"
    priority = 10
    batch_size = NOISE_BATCH
    deterministic = False  # the kicks live here: no reference driver, no no-return rule

    @classmethod
    def applies(cls, plan) -> bool:
        return plan.noise is not None

    def __init__(self, scene, ta, layout, ics, traj_ids, **config):
        super().__init__(scene, ta, layout, ics, traj_ids, **config)
        self.P = kick_interval(scene)
        self.n_epochs_max = max(1, round(scene.t_max / self.P))
        self.c, self.s = ou_coefficients(float(scene.gamma), float(scene.noise_strength), 0.5 * self.P)
        self.traj_ids = np.asarray(traj_ids, dtype=np.int64).tolist()
        self.streams = [None] * self.B
        self.normals = np.zeros((self.B, BLOCK, 4))
        self.kicks = np.zeros(self.B, dtype=np.int64)  # kicks of the lane's orbit so far
        self.n_kicks = 0  # kick epochs run (Python rounds: for the benchmark)

    def load_orbit(self, lane, k):
        super().load_orbit(lane, k)
        self.streams[lane] = orbit_stream(self.scene.seed, self.traj_ids[k])
        self.kicks[lane] = 0

    def _draw(self, live):
        """(B, 4) normals: those of every live lane's current kick (refilling the lanes at a block's end)."""
        row = self.kicks % BLOCK
        for lane in np.flatnonzero(live & (row == 0)):
            self.normals[lane] = self.streams[lane].standard_normal((BLOCK, 4))
        return self.normals[np.arange(self.B), row]

    def run(self):
        B, ta, P, K = self.B, self.ta, self.P, self.n_epochs_max
        orbit, st = self.orbit, self.state
        c, s = self.c, self.s
        p = st[2:4]  # view (2, B) of the momenta
        n_returns = n_steps = 0
        lanes = range(B)
        for lane in lanes:
            self.load_next(lane)
        while True:
            live = np.array(orbit) >= 0
            if not live.any():
                break
            ta.set_time(self.zeros)
            xi = self._draw(live)
            p[:, live] = c * p[:, live] + s * xi[live, :2].T
            ta.propagate_until(P)
            n_returns += 1
            n_steps += self._checked()
            still = np.array(orbit) >= 0  # an orbit that escaped in the epoch is parked: no kick
            p[:, still] = c * p[:, still] + s * xi[still, 2:].T
            self.kicks[live] += 1
            self._end_epoch(np.flatnonzero(still).tolist(), lambda lane, k: k >= K)  # t_max: after its last kick
        self.n_kicks = n_returns
        e = np.empty(0)
        return n_returns, n_steps, (np.empty(0, np.int64), e, e)
