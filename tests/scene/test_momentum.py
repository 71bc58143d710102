"""The momentum convention of region ICs: 'tangential' (default, unchanged) and 'random' directions."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from old_code import code_at
from scipy import stats

from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles
from hhscatter.scene.ics import BLOCK, region_ics
from hhscatter.scene.scene import Scene, SectionWindow, scene_from_dict

ROOT = Path(__file__).resolve().parents[2]
BASE = "fa21699"  # the code before the momentum option
M = HenonHeiles()


def _angles(ics):
    """(θ, α): the momentum's direction and its angle to the position vector, both in [0, 2π)."""
    x, y, px, py = ics.T
    theta = np.arctan2(py, px) % (2 * np.pi)
    return theta, (theta - np.arctan2(y, x)) % (2 * np.pi)


def _uniform_p(a):
    return stats.kstest(a, stats.uniform(0, 2 * np.pi).cdf).pvalue


def test_random_directions_are_uniform_and_independent_of_the_position():
    sc = Scene(energy=0.3, n=100_000, seed=7, momentum="random")
    ics = region_ics(sc, 0, sc.n)
    theta, alpha = _angles(ics)
    assert _uniform_p(theta) > 1e-3 and _uniform_p(alpha) > 1e-3
    # independence of position and direction: quadrant of φ against quadrant of α (chi² on a 4×4 table)
    phi = np.arctan2(ics[:, 1], ics[:, 0]) % (2 * np.pi)
    table = np.histogram2d(phi, alpha, bins=4, range=[[0, 2 * np.pi]] * 2)[0]
    assert stats.chi2_contingency(table).pvalue > 1e-3
    # the same tests reject what a wrong sampler would give: directions on a half circle, or tangential ones
    half = np.column_stack([ics[:, :2], -np.abs(ics[:, 2]), ics[:, 3]])  # px ≤ 0 only
    assert _uniform_p(_angles(half)[0]) < 1e-6
    tangential = region_ics(sc.replace(momentum="tangential"), 0, sc.n)
    assert _uniform_p(_angles(tangential)[1]) < 1e-6  # α = π/2 always
    # a slight bias (directions drawn as θ + 0.05 sin θ) is seen too at this N
    bent = theta + 0.05 * np.sin(theta)
    assert _uniform_p(bent % (2 * np.pi)) < 1e-3


@pytest.mark.parametrize("region", ["disk", "well", "square"])
def test_random_momenta_have_the_energy_exactly_and_the_positions_of_tangential(region):
    E = 0.35
    sc = Scene(energy=E, n=20_000, seed=3, region=region, momentum="random")
    ics = region_ics(sc, 0, sc.n)
    e = 0.5 * (ics[:, 2] ** 2 + ics[:, 3] ** 2) + M.potential(ics[:, 0], ics[:, 1])
    assert np.abs(e / E - 1).max() <= 1e-14
    tan = region_ics(sc.replace(momentum="tangential"), 0, sc.n)
    assert np.array_equal(ics[:, :2], tan[:, :2])  # the angles are drawn after the positions
    # not on the section: ṙ = (x px + y py)/r is spread over both signs
    rdot = ics[:, 0] * ics[:, 2] + ics[:, 1] * ics[:, 3]
    assert 0.45 < (rdot > 0).mean() < 0.55


def test_random_momenta_do_not_depend_on_the_chunks():
    sc = Scene(energy=0.3, n=3 * BLOCK, seed=11, momentum="random", chunk_size=1000)
    k, j, m = 1000, BLOCK + 123, 3 * BLOCK - 7  # across block boundaries
    whole = region_ics(sc, k, m)
    assert np.array_equal(whole, np.concatenate([region_ics(sc, k, j), region_ics(sc, j, m)]))
    assert np.array_equal(whole[5], region_ics(sc, k + 5, k + 6)[0])
    # and another seed gives other directions at the same orbit index
    other = region_ics(sc.replace(seed=12), k, m)
    assert not np.array_equal(whole[:, 2:], other[:, 2:])


_OLD_ICS = """
import hashlib, sys
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene
for region in ("disk", "well", "square"):
    sc = Scene(energy=0.33, n=9000, seed=5, region=region, r_esc=1.03)
    a = region_ics(sc, 100, 9000)
    print(region, hashlib.sha256(a.tobytes()).hexdigest(), sc.result_hash())
"""


def test_default_scenes_give_the_ics_and_hashes_of_main_before_the_option(tmp_path):
    old = code_at(BASE, tmp_path / "old")

    def run(root):
        env = {**os.environ, "PYTHONPATH": str(root)}
        r = subprocess.run([sys.executable, "-c", _OLD_ICS], cwd=tmp_path, env=env, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr[-2000:]
        return r.stdout

    before, after = run(old), run(ROOT)
    assert len(before.splitlines()) == 3 and after == before


def test_the_option_is_left_out_of_the_identity_at_its_default():
    a = Scene(energy=0.3, n=100, gamma=0.01, seed=2)
    assert "momentum" not in a.to_dict()
    assert a.replace(momentum="tangential").result_hash() == a.result_hash()
    r = a.replace(momentum="random")
    assert r.to_dict()["momentum"] == "random" and r.result_hash() != a.result_hash()
    assert scene_from_dict(r.to_dict()) == r and scene_from_dict(a.to_dict()) == a


def test_bad_momentum_is_refused_with_the_key_and_the_allowed_values(tmp_path):
    for bad in ("radial", "Random", 1, None):
        with pytest.raises(ConfigError, match=r"momentum must be one of \('tangential', 'random'\)"):
            Scene(energy=0.3, n=10, momentum=bad)
    ics = tmp_path / "ics.csv"
    ics.write_text("x,y,px,py\n0.1,0.0,0.0,0.7\n")
    with pytest.raises(ConfigError, match="momentum = 'random' is an option of region ICs"):
        Scene(energy=None, n=1, ics=str(ics), momentum="random")
    Scene(energy=None, n=1, ics=str(ics))  # the default is fine with a table
    # in a scene file: the strict check names the key and the values, before any work
    from hhscatter.scene.schema import load_scene

    (tmp_path / "a.toml").write_text('[scene]\nenergy = 0.3\nn = 10\nmomentum = "radial"\n')
    with pytest.raises(ConfigError, match=r"momentum.*one of 'tangential', 'random'"):
        load_scene(tmp_path / "a.toml")
    (tmp_path / "b.toml").write_text('[scene]\nenergy = 0.3\nn = 10\nregion = "well"\nmomentum = "random"\n')
    assert load_scene(tmp_path / "b.toml").momentum == "random"


def test_cli_refuses_a_bad_momentum_in_a_scene_file_with_exit_2(tmp_path):
    hh = Path(sys.executable).parent / "hhscatter"
    (tmp_path / "a.toml").write_text('[scene]\nenergy = 0.3\nn = 10\nmomentum = "radial"\n')
    r = subprocess.run(
        [str(hh), "simulate", str(tmp_path / "a.toml"), "--out", str(tmp_path / "run")], capture_output=True, text=True
    )
    assert r.returncode == 2 and "momentum" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "run").exists()


def _first_crossings_reference(ic, gamma, t_end):
    """Section crossings (ṙ = 0 with φ̇ > 0) of one orbit up to t_end, by scipy's DOP853 at rtol 1e-12 (an
    integrator independent of the engine's Taylor method)."""
    from scipy.integrate import solve_ivp

    def f(t, s):
        x, y, px, py = s
        return [px, py, -x - 2 * x * y - gamma * px, -y - x * x + y * y - gamma * py]

    def rdot(t, s):
        return s[0] * s[2] + s[1] * s[3]

    sol = solve_ivp(f, (0, t_end), ic, method="DOP853", rtol=1e-12, atol=1e-14, events=rdot)
    t, s = sol.t_events[0], np.reshape(sol.y_events[0], (-1, 4))
    keep = (s[:, 0] * s[:, 3] - s[:, 1] * s[:, 2] > 0) & (t > 1e-10)
    return t[keep], s[keep]


def test_sections_are_recorded_for_random_momenta_as_by_an_independent_integrator():
    from hhscatter.integrate.engine import run_chunk

    sc = Scene(energy=0.3, n=40, gamma=0.01, seed=9, momentum="random", t_max=12.0, sections=SectionWindow(t_to=12.0))
    ics = region_ics(sc, 0, sc.n)
    res = run_chunk(sc, ics, np.arange(sc.n))
    sec = res.sections
    x, y, px, py = sec["x"], sec["y"], sec["px"], sec["py"]
    assert len(x) > 40 and (sec["t"] > 0).all()
    assert np.abs(x * px + y * py).max() <= 1e-13 and (x * py - y * px > 0).all()
    # orbits that start moving inwards (ṙ < 0) and outwards both have section points
    rdot0 = ics[:, 0] * ics[:, 2] + ics[:, 1] * ics[:, 3]
    has = np.isin(np.arange(sc.n), sec["traj_id"])
    assert has[rdot0 < 0].any() and has[rdot0 > 0].any()
    for k in range(16):
        t_end = float(res.lifetimes["t_end"][k])
        ref_t, ref_s = _first_crossings_reference(ics[k], sc.gamma, t_end)
        mine = sec["t"][sec["traj_id"] == k]
        assert len(mine) == len(ref_t), k
        np.testing.assert_allclose(mine, ref_t, rtol=0, atol=1e-8)
