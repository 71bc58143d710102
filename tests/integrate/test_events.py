"""The events' expressions: a root that heyoka can locate in every step, the first one included."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hhscatter.integrate.engine import SETTLED, run_chunk, simulate_orbit
from hhscatter.integrate.events import zero_power_start
from hhscatter.integrate.plan import plan_of
from hhscatter.model import HenonHeiles
from hhscatter.scene.ics import section_velocities
from hhscatter.scene.scene import Scene

GAMMA = 0.01


def _settling_time(ic, e_c):
    """The first time the energy of the damped Hénon–Heiles orbit from ``ic`` falls to E_c: an independent
    integration (scipy's DOP853 on Hamilton's equations with the linear drag written out, its event on H − E_c)."""

    def rhs(t, s):
        x, y, px, py = s
        return [px, py, -x - 2 * x * y - GAMMA * px, -y - (x * x - y * y) - GAMMA * py]

    def below(t, s):
        x, y, px, py = s
        return 0.5 * (px * px + py * py) + 0.5 * (x * x + y * y) + x * x * y - y * y * y / 3 - e_c

    below.terminal, below.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 50.0), ic, method="DOP853", rtol=1e-13, atol=1e-15, events=below)
    assert sol.t_events[0].size == 1
    return sol.t_events[0][0]


@pytest.mark.parametrize("xy", [(0.05, 0.0), (0.1, 0.0), (0.0, 0.05), (0.12, 0.03)])
def test_orbit_whose_energy_crosses_critical_energy_in_its_first_step_settles(xy):
    """E0 = E_c + 10⁻³ from a point of the well: the energy crosses E_c in the orbit's first step (t ≈ 0.31). The
    orbit settles there, on the batch engine and on the reference driver, at the time an independent integration
    finds, with no event failure. (A start on y = 0 exactly used to lose the E = E_c event in that step: heyoka's
    Taylor coefficients of y³ divide by y; the orbit ran on to t_max, censored.)"""
    m = HenonHeiles()
    e0 = m.critical_energy + 1e-3
    x, y = np.array([xy[0]]), np.array([xy[1]])
    px, py = section_velocities(m, x, y, e0)
    ic = np.array([x[0], y[0], px[0], py[0]])
    scene = Scene(energy=e0, gamma=GAMMA, n=1)
    t_ref = _settling_time(ic, m.critical_energy)
    assert t_ref < 0.5
    res = run_chunk(scene, ic[None, :], np.arange(1))
    lt = res.lifetimes
    assert lt["outcome"][0] == SETTLED, lt
    assert lt["t_end"][0] == pytest.approx(t_ref, rel=1e-9)
    assert lt["e_end"][0] == pytest.approx(m.critical_energy, abs=1e-12)
    assert res.event_failures == 0
    ref = simulate_orbit(scene, ic)
    assert ref.outcome == SETTLED and float(ref.t_end) == pytest.approx(t_ref, rel=1e-9)


def test_zero_power_start_marks_starts_on_the_base_of_a_cube():
    """Hénon–Heiles' H holds y³ (x² is a square): the orbits that start at y = 0 exactly, in drag scenes only."""
    ics = np.array([[0.05, 0.0, 0.0, 0.58], [0.0, 0.05, 0.58, 0.0], [0.05, 1e-300, 0.0, 0.58]])
    assert zero_power_start(plan_of(Scene(energy=0.17, n=3, gamma=GAMMA)), ics).tolist() == [True, False, False]
    assert zero_power_start(plan_of(Scene(energy=0.17, n=3)), ics) is None
