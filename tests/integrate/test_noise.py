"""The noise scheduler (hhscatter.integrate.noise): determinism, the invariant measure, agreement in distribution
with an independent integrator, and a short Kramers–Langer check."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from hhscatter.analysis.noise import kramers_langer, thermal_rate
from hhscatter.integrate.batch import _batch_integrator
from hhscatter.integrate.engine import CENSORED, ESCAPED, run_chunk
from hhscatter.integrate.lanes import _bind
from hhscatter.integrate.noise import _Noisy, orbit_stream
from hhscatter.integrate.noise_reference import obabo_escape_times
from hhscatter.integrate.plan import plan_of
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Noise, Scene


def _bitwise(a: dict, b: dict, what):
    for col, v in a.items():
        assert v.dtype == b[col].dtype and v.tobytes() == b[col].tobytes(), (what, col)


def _split(scene, ics, ids, size, batch_size):
    parts = [
        run_chunk(scene, ics[a : a + size], ids[a : a + size], batch_size=batch_size).lifetimes
        for a in range(0, len(ics), size)
    ]
    return {c: np.concatenate([p[c] for p in parts]) for c in parts[0]}


@pytest.mark.parametrize(
    "noise, gamma", [(Noise(temperature=1 / 12), 1.0), (Noise(sigma=0.04), 0.0)], ids=["heat-bath", "no-drag"]
)
def test_noise_tables_do_not_depend_on_chunk_or_batch_size(noise, gamma):
    sc = Scene(energy=0.16, n=300, gamma=gamma, t_max=40.0, seed=4, noise=noise)
    ics = region_ics(sc, 0, sc.n)
    ids = np.arange(sc.n, dtype=np.int64)
    whole = run_chunk(sc, ics, ids).lifetimes
    out = whole["outcome"]
    assert (out == ESCAPED).sum() > 30 and (out == CENSORED).sum() > 30
    _bitwise(whole, _split(sc, ics, ids, 37, 4), "chunks of 37, 4 lanes")
    _bitwise(whole, _split(sc, ics, ids, 128, 16), "chunks of 128, 16 lanes")


def test_noise_runs_are_byte_identical_whatever_the_workers(tmp_path):
    from hhscatter.data.read import read_lifetimes
    from hhscatter.run.runner import simulate

    sc = Scene(energy=0.2, n=120, gamma=1.0, t_max=30.0, seed=9, chunk_size=50, noise=Noise(temperature=1 / 12))
    simulate(sc, tmp_path / "one", workers=1, progress=False)
    simulate(sc.replace(chunk_size=32), tmp_path / "two", workers=2, progress=False)
    a, b = (read_lifetimes(tmp_path / d).sort_values("traj_id").reset_index(drop=True) for d in ("one", "two"))
    assert a["outcome"].astype(str).tolist() == b["outcome"].astype(str).tolist()
    assert set(a["outcome"].astype(str)) == {"escaped", "censored"}
    for col in ("t_end", "e_end", "exit_channel"):
        assert a[col].to_numpy().tobytes() == b[col].to_numpy().tobytes(), col


def test_an_orbits_kicks_depend_on_seed_and_traj_id_only():
    a = orbit_stream(3, 17).standard_normal((5, 4))
    assert (a == orbit_stream(3, 17).standard_normal((5, 4))).all()
    assert not (a == orbit_stream(4, 17).standard_normal((5, 4))).any()
    assert not (a == orbit_stream(3, 18).standard_normal((5, 4))).any()
    # the same initial state under two traj_ids: two different noisy orbits
    sc = Scene(energy=0.2, n=2, gamma=1.0, t_max=30.0, seed=9, noise=Noise(temperature=1 / 12))
    ics = np.repeat(region_ics(sc, 0, 1), 2, axis=0)
    res = run_chunk(sc, ics, np.array([5, 6]))
    assert res.lifetimes["e_end"][0] != res.lifetimes["e_end"][1]


def _end_states(scene, ics):
    """Every orbit's outcome and end state (x, y, px, py), from the scheduler's lanes."""
    plan = plan_of(scene)
    with _batch_integrator(plan, 64) as (ta, specs, layout):
        lanes = _Noisy(plan, ta, layout, ics, np.arange(len(ics)))
        _bind(ta, specs, lanes, lanes.handlers)
        try:
            lanes.run()
        finally:
            lanes.close()
    return np.array(lanes.outcome), np.array(lanes.end_state, dtype=float)


def _boltzmann_r_cdf(model, T, r_max=1.0, nr=4000, nth=720):
    """The Boltzmann distribution of r = |q| in the well (density ∝ e^{−V/T} on r < r_max), by quadrature."""
    r = np.linspace(0.0, r_max, nr)
    th = np.linspace(0.0, 2 * np.pi, nth, endpoint=False)
    R, TH = np.meshgrid(r, th, indexing="ij")
    w = np.exp(-model.potential(R * np.cos(TH), R * np.sin(TH)) / T).mean(axis=1) * r
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(r))])
    return r, cdf / cdf[-1]


@pytest.mark.parametrize("kick", [None, 0.5], ids=["default-kick", "largest-kick"])
def test_the_invariant_measure_is_boltzmann_at_any_kick(kick):
    """A deep well (ΔE/T = 10: escape within t_max has probability ~1e-4): ⟨K⟩ = T (equipartition, two degrees of
    freedom) and the distribution of r against the Boltzmann density e^{−V/T} (quadrature). The splitting
    preserves e^{−H/T} exactly, so even the largest allowed kick interval gives it."""
    T = 1 / 60
    sc = Scene(energy=0.01, n=3000, gamma=1.0, t_max=30.0, seed=2, noise=Noise(temperature=T, kick=kick))
    outcome, end = _end_states(sc, region_ics(sc, 0, sc.n))
    assert (outcome == ESCAPED).sum() <= 5  # k t_max n ≈ 0.7 expected
    end = end[outcome == CENSORED]
    K = 0.5 * (end[:, 2] ** 2 + end[:, 3] ** 2)
    assert abs(K.mean() / T - 1) < 3 / math.sqrt(sc.n)  # K/T ~ Exp(1): std 1
    r_grid, cdf = _boltzmann_r_cdf(sc.model, T)
    p = stats.kstest(np.hypot(end[:, 0], end[:, 1]), lambda x: np.interp(x, r_grid, cdf)).pvalue
    assert p > 1e-3
    # radii 5 % off are rejected at this sample size: the test has power
    off = stats.kstest(np.hypot(end[:, 0], end[:, 1]) * 1.05, lambda x: np.interp(x, r_grid, cdf)).pvalue
    assert off < 1e-3


def test_escape_times_agree_in_distribution_with_an_independent_obabo():
    """Engine (exact-event flow, kick 0.1) and the numpy OBABO (Verlet, h = 0.01): two-sample KS on the escape
    times of the same initial states (ΔE/T = 2); a 30 % hotter reference is rejected (the test has power)."""
    T, gamma, n, t_max = 1 / 12, 1.0, 400, 100.0
    sc = Scene(energy=0.1, n=n, gamma=gamma, t_max=t_max, seed=7, noise=Noise(temperature=T))
    ics = region_ics(sc, 0, n)
    lt = run_chunk(sc, ics, np.arange(n)).lifetimes
    ref = dict(h=0.01, t_max=t_max, r_esc=sc.r_esc, seed=1, gamma=gamma)
    t_ref, esc_ref = obabo_escape_times(sc.model, ics, sigma=math.sqrt(2 * gamma * T), **ref)
    assert stats.ks_2samp(lt["t_end"], t_ref).pvalue > 1e-3
    assert abs((lt["outcome"] == ESCAPED).mean() - esc_ref.mean()) < 4 * math.sqrt(0.25 / n)
    t_hot, _ = obabo_escape_times(sc.model, ics, sigma=math.sqrt(2 * gamma * 1.3 * T), **ref)
    assert stats.ks_2samp(lt["t_end"], t_hot).pvalue < 1e-3


def test_escape_rate_against_kramers_langer_at_a_low_barrier():
    """γ = 1, ΔE/T = 3 (Hénon–Heiles, three saddles): the long-time rate within 15 % of Kramers–Langer (its
    finite-barrier correction at ΔE/T = 3 is a few per cent; the statistical error here ≈ 4 %)."""
    T, n, t_max = (1 / 6) / 3, 1000, 200.0
    sc = Scene(energy=0.05, n=n, gamma=1.0, t_max=t_max, seed=11, tol=1e-12, noise=Noise(temperature=T))
    lt = run_chunk(sc, region_ics(sc, 0, n), np.arange(n)).lifetimes
    rate = thermal_rate(lt["t_end"], lt["outcome"] == ESCAPED, 20.0, t_max)
    ratio = rate.rate / kramers_langer(sc.model, 1.0, T).rate
    assert rate.n_events > 500
    assert abs(ratio - 1) < 0.15, (ratio, rate.rate_err / rate.rate)


def test_the_scalar_reference_driver_refuses_a_noise_scene():
    """It would integrate the flow without the kicks: refused, not run."""
    from hhscatter.integrate.engine import simulate_orbit

    sc = Scene(energy=0.1, n=1, gamma=1.0, noise=Noise(temperature=0.05))
    with pytest.raises(ValueError, match="no reference driver"):
        simulate_orbit(sc, [0.1, 0.0, 0.0, 0.1])
