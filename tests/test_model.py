"""Closed forms of the model and the initial conditions."""

import numpy as np
import pytest

from hhscatter.model import HenonHeiles, equations, hamilton_equations
from hhscatter.scene.ics import BLOCK, region_ics
from hhscatter.scene.scene import Scene


@pytest.mark.parametrize("omega,lam", [(1.0, 1.0), (1.3, 0.7)])
def test_saddles_are_critical_points_at_critical_energy(omega, lam):
    m = HenonHeiles(omega, lam)
    x, y = m.saddles.T
    # ∇V = 0 at the saddles (finite differences of the numpy potential)
    h = 1e-6
    gx = (m.potential(x + h, y) - m.potential(x - h, y)) / (2 * h)
    gy = (m.potential(x, y + h) - m.potential(x, y - h)) / (2 * h)
    assert np.allclose(gx, 0, atol=1e-8) and np.allclose(gy, 0, atol=1e-8)
    assert np.allclose(m.potential(x, y), m.critical_energy, rtol=1e-14)
    assert np.allclose(np.hypot(x, y), m.saddle_radius)
    assert list(m.exit_channel(x, y)) == [0, 1, 2]


def test_paper_values():
    m = HenonHeiles()
    assert m.critical_energy == pytest.approx(1 / 6, rel=1e-15)
    assert m.saddle_radius == 1.0


def test_simplified_rhs_equals_hamilton_equations():
    import heyoka as hy

    for m in (HenonHeiles(), HenonHeiles(1.3, 0.7)):
        a = hy.cfunc([rhs for _, rhs in equations(m, hy)], vars=hy.make_vars("x", "y", "px", "py"))
        b = hy.cfunc([rhs for _, rhs in hamilton_equations(m, hy)], vars=hy.make_vars("x", "y", "px", "py"))
        pts = np.random.default_rng(0).uniform(-1.5, 1.5, (4, 200))
        assert np.allclose(a(pts), b(pts), rtol=4 * np.finfo(float).eps, atol=8 * np.finfo(float).eps)


@pytest.mark.parametrize("region", ["disk", "well"])
def test_initial_conditions_on_section_at_energy(region):
    sc = Scene(energy=0.25, n=10, seed=5, region=region)
    s = region_ics(sc, 0, 3000)
    x, y, px, py = s.T
    m = sc.model
    assert np.allclose(m.energy(x, y, px, py), 0.25, rtol=8 * np.finfo(float).eps)
    assert np.abs(x * px + y * py).max() < 1e-15  # ṙ = 0
    assert (x * py - y * px > 0).all()  # φ̇ > 0
    if region == "disk":
        assert np.hypot(x, y).max() < 0.5
        # uniform in area: the fraction inside r < 0.25 is 1/4
        frac = (np.hypot(x, y) < 0.25).mean()
        assert abs(frac - 0.25) < 4 * np.sqrt(0.25 * 0.75 / len(x))
    else:
        assert m.inside_triangle(x, y).all() and (m.potential(x, y) < 0.25).all()


def test_ics_do_not_depend_on_chunking():
    sc = Scene(energy=0.3, n=10, seed=9)
    whole = region_ics(sc, 0, 3 * BLOCK)
    parts = np.concatenate([region_ics(sc, a, min(a + 1000, 3 * BLOCK)) for a in range(0, 3 * BLOCK, 1000)])
    assert np.array_equal(whole, parts)
    assert not np.array_equal(region_ics(sc.replace(seed=10), 0, 100), whole[:100])
