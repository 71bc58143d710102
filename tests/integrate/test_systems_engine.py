"""The engine on every built-in system and a declared expression: energy conservation, escape times
against a long-double reference, the closure at E = E_c inside Ω, and the exit fractions of symmetric systems."""

import numpy as np
import pytest
from scipy import stats

from hhscatter.integrate.engine import CENSORED, ESCAPED, SETTLED, run_chunk, simulate_orbit
from hhscatter.model.spec import system_from_spec
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene

#: (system spec, number of exits, symmetric: every exit equivalent)
SYSTEMS = [
    pytest.param({"name": "n_exit", "params": {"n": 3}}, 3, True, id="n_exit3"),
    pytest.param({"name": "n_exit", "params": {"n": 4}}, 4, True, id="n_exit4"),
    pytest.param({"name": "contopoulos", "params": {"eps": 0.25}}, 4, True, id="contopoulos"),
    pytest.param({"name": "barbanis"}, 2, True, id="barbanis"),
    pytest.param(
        {"potential": "0.5*(x**2 + y**2) - eps*x**2*y**2", "params": {"eps": 0.5}}, 4, True, id="declared-contopoulos"
    ),
]


def _scene(spec, ratio=1.5, **kw):
    m = system_from_spec(spec)
    kw.setdefault("radius", 0.5 * m.saddle_radius)
    return Scene(energy=ratio * m.critical_energy, system=spec, **kw)


@pytest.mark.parametrize("spec, n_exits, symmetric", SYSTEMS)
def test_energy_conserved_and_escape_times_against_long_double(spec, n_exits, symmetric):
    sc = _scene(spec, n=60, seed=2, t_max=500.0, momentum="random")
    assert len(sc.model.exits) == n_exits
    ics = region_ics(sc, 0, sc.n)
    lt = run_chunk(sc, ics, np.arange(sc.n)).lifetimes
    rel = np.abs(lt["e_end"] - lt["e0"]) / lt["e0"]
    assert rel.max() <= 1e-13, rel.max()  # tol 1e-15: two orders of margin, any time up to t_max
    t = lt["t_end"]
    short = np.flatnonzero((lt["outcome"] == ESCAPED) & (t < 15.0))[:4]
    assert len(short) >= 2
    for k in short:
        ref = simulate_orbit(sc, ics[k], fp_type=np.longdouble)
        assert ref.outcome == ESCAPED
        assert abs(float(ref.t_end) - t[k]) / t[k] <= 1e-10


@pytest.mark.parametrize("spec, n_exits, symmetric", SYSTEMS[:1] + SYSTEMS[2:3])
def test_dissipative_orbits_settle_at_the_critical_energy_inside_omega(spec, n_exits, symmetric):
    sc = _scene(spec, ratio=1.2, n=40, seed=3, gamma=0.05, t_max=3000.0)
    ics = region_ics(sc, 0, sc.n)
    res = run_chunk(sc, ics, np.arange(sc.n))
    lt = res.lifetimes
    settled = lt["outcome"] == SETTLED
    assert settled.sum() >= 3 and (lt["outcome"] != CENSORED).all()
    assert np.abs(lt["e_end"][settled] - sc.model.critical_energy).max() <= 1e-12


@pytest.mark.parametrize("spec, n_exits, symmetric", SYSTEMS)
def test_symmetric_systems_share_escapes_equally_among_their_exits(spec, n_exits, symmetric):
    """At E = 3 E_c from a disk centred on the minimum with random momenta, every exit takes 1/n of the
    escapes: each share within 3σ (binomial) and a χ² test of the counts at p > 0.001 (seed fixed)."""
    sc = _scene(spec, ratio=3.0, n=3000, seed=11, t_max=200.0, momentum="random")
    lt = run_chunk(sc, region_ics(sc, 0, sc.n), np.arange(sc.n)).lifetimes
    ch = lt["exit_channel"][lt["outcome"] == ESCAPED]
    counts = np.bincount(ch, minlength=n_exits)
    assert len(counts) == n_exits
    m = counts.sum()
    share, sigma = counts / m, np.sqrt((1 / n_exits) * (1 - 1 / n_exits) / m)
    assert np.all(np.abs(share - 1 / n_exits) < 3 * sigma), share
    assert stats.chisquare(counts).pvalue > 1e-3, counts
