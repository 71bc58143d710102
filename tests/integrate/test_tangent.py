"""The tangent dynamics (``Scene(tangent=True)``): the log-stretch Λ at t_end against an independent variational
integration (scipy's DOP853 of the linearised flow, renormalised by Gram–Schmidt), the orbits' steps, ends and
section points those of the scene without it (bit for bit), the saddle's eigenvalue, determinism, and scenes
without it unchanged."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import heyoka as hy
import numpy as np
import pytest
from old_code import code_at
from scipy.integrate import solve_ivp

from hhscatter.data.read import read_lifetimes, read_sections
from hhscatter.errors import ConfigError
from hhscatter.integrate import events
from hhscatter.integrate.engine import CENSORED, ESCAPED, run_chunk, simulate_orbit
from hhscatter.integrate.plan import plan_of
from hhscatter.run.runner import simulate
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene, SectionWindow

ROOT = Path(__file__).resolve().parents[2]
BASE = "98b437a"  # the code before the tangent option
DECLARED = {"potential": "0.5*(x**2 + y**2) - eps*x**2*y**2", "params": {"eps": 0.5}, "dissipation": "quadratic"}


def _hh_field(gamma):
    """Hénon–Heiles with linear drag: the flow f and its Jacobian A, written out by hand."""

    def f(q):
        x, y, px, py = q
        return np.array([px, py, -x - 2 * x * y - gamma * px, -y - x * x + y * y - gamma * py])

    def jac(q):
        x, y, px, py = q
        return np.array(
            [[0, 0, 1, 0], [0, 0, 0, 1], [-1 - 2 * y, -2 * x, -gamma, 0], [-2 * x, -1 + 2 * y, 0, -gamma]], float
        )

    return f, jac


def _declared_field(gamma, eps=0.5):
    """V = (x² + y²)/2 − εx²y² with quadratic drag −γ|p|p, by hand."""

    def f(q):
        x, y, px, py = q
        p = np.hypot(px, py)
        return np.array([px, py, -x + 2 * eps * x * y * y - gamma * p * px, -y + 2 * eps * x * x * y - gamma * p * py])

    def jac(q):
        x, y, px, py = q
        p = np.hypot(px, py)
        dp = -gamma * (p * np.eye(2) + np.outer([px, py], [px, py]) / p)
        a = np.zeros((4, 4))
        a[0, 2] = a[1, 3] = 1.0
        a[2:, :2] = [[-1 + 2 * eps * y * y, 4 * eps * x * y], [4 * eps * x * y, -1 + 2 * eps * x * x]]
        a[2:, 2:] = dp
        return a

    return f, jac


def _reference_stretch(field, q0, u0, t_end, renorm=0.5):
    """ln|δq(t_end)|/|δq(0)| from δq(0) = u0: DOP853 (rtol 1e-12) of (q, δq), δq renormalised to 1 every
    ``renorm`` (Gram–Schmidt with one vector), the logarithms of the norms summed."""
    f, jac = field

    def rhs(t, z):
        return np.concatenate([f(z[:4]), jac(z[:4]) @ z[4:]])

    z = np.concatenate([q0, u0])
    total, t = 0.0, 0.0
    while t < t_end:
        t1 = min(t + renorm, t_end)
        sol = solve_ivp(rhs, (t, t1), z, method="DOP853", rtol=1e-12, atol=1e-14)
        z = sol.y[:, -1]
        n = np.linalg.norm(z[4:])
        total += np.log(n)
        z[4:] /= n
        t = t1
    return total


@pytest.mark.parametrize(
    "case",
    [
        pytest.param(dict(energy=0.2, gamma=0.0), id="hh-conservative"),
        pytest.param(dict(energy=0.25, gamma=0.02), id="hh-linear-drag"),
        pytest.param(dict(system=DECLARED, gamma=0.01), id="declared-quadratic-drag"),
    ],
)
def test_log_stretch_matches_an_independent_renormalised_variational_integration(case):
    case = dict(case)
    declared = "system" in case
    if declared:
        ec = Scene(energy=1.0, n=1, system=DECLARED).model.critical_energy
        case["energy"] = 1.3 * ec
    sc = Scene(n=16, seed=4, t_max=25.0, tangent=True, **case)
    if declared:
        sc = sc.replace(radius=0.5 * sc.model.saddle_radius)
    ics = region_ics(sc, 0, sc.n)
    lt = run_chunk(sc, ics, np.arange(sc.n)).lifetimes
    assert (lt["t_end"] > 0).all()
    field = _declared_field(sc.gamma) if declared else _hh_field(sc.gamma)
    u0 = events.tangent_start(plan_of(sc), ics)
    checked = 0
    for k in range(sc.n):
        ref = _reference_stretch(field, ics[k], u0[k], lt["t_end"][k])
        # both integrations at ~1e-12 relative, their difference amplified by the stretching itself: e^Λ
        bound = 1e-9 * max(1.0, np.exp(ref))
        assert abs(lt["log_stretch"][k] - ref) <= bound, (k, lt["log_stretch"][k], ref, bound)
        checked += 1
    assert checked == sc.n
    assert np.ptp(lt["log_stretch"] / lt["t_end"]) > 0.01  # the orbits differ: not a constant that passes


def test_the_compiled_tangent_dynamics_leave_every_step_of_the_flow_unchanged():
    """An orbit below E_c (bounded, chaotic; E = 0.153): heyoka's steps and the states x, y, p_x, p_y of the system with the tangent
    dynamics equal those of the flow alone at every step, bit for bit, while the vector stretches by e^Λ."""
    plain, tan = (plan_of(Scene(energy=0.2, n=1, t_max=400.0, tangent=t)) for t in (False, True))
    ic = np.array([0.0, -0.2, 0.5, 0.1])
    a = hy.taylor_adaptive(events.system(plain, plain.layout), np.r_[ic, np.zeros(plain.layout.n_state - 4)], tol=1e-15)
    st = np.zeros(tan.layout.n_state)
    st[:4] = ic
    st[tan.layout.tangent : tan.layout.tangent + 4] = events.tangent_start(tan, ic[None])[0] * events.TANGENT_NORM
    b = hy.taylor_adaptive(events.system(tan, tan.layout), st, tol=1e-15)
    steps = 0
    while a.time < 300.0:
        ha, hb = a.step()[1], b.step()[1]
        assert ha == hb and a.state[:4].tobytes() == b.state[:4].tobytes(), (steps, ha, hb)
        steps += 1
    assert steps > 500
    lam = events.log_stretch(*b.state[tan.layout.tangent : tan.layout.tangent + 4])
    assert lam > 10.0  # the vector stretched e^10-fold (a chaotic orbit) and never set a step


def test_the_saddle_rest_point_stretches_at_its_eigenvalue():
    """Near the Hénon–Heiles saddle (0, 1) (E → E_c, the shrinking Lyapunov orbit) the linearised flow has
    ÿ = +δy (V_yy = −1): the stretch rate is the eigenvalue 1; at the rest point itself u(0) = (1, 0, 0, 0) lies
    in the oscillating direction, ẍ = −3δx: Λ(t) = ½ ln(cos²√3t + 3 sin²√3t) (the compiled equations: at a rest
    point the flow sets no step)."""
    a = 1e-6
    near = np.array([[a, 1.0, 0.0, 0.0]])  # E − E_c = 3a²/2: on the smallest Lyapunov orbit to O(a²)
    stretch = {}
    for t_max in (8.0, 14.0):
        sc = Scene(energy=1.0 / 6.0 + 1e-9, n=1, tangent=True, t_max=t_max)
        lt = run_chunk(sc, near, np.arange(1)).lifetimes
        assert lt["outcome"][0] == CENSORED
        stretch[t_max] = lt["log_stretch"][0]
    rate = (stretch[14.0] - stretch[8.0]) / 6.0
    assert abs(rate - 1.0) <= 1e-5, rate
    # at the rest point itself the flow has no Taylor coefficient to set a step (the engine's steps are the flow's):
    # the compiled equations, with δq(0) = (1, 0, 0, 0) of norm 1 setting the steps, give the oscillation exactly
    sc = plan_of(Scene(energy=0.17, n=1, tangent=True, t_max=9.0))
    lay = sc.layout
    st = np.zeros(lay.n_state)
    st[:4], st[lay.tangent] = (0.0, 1.0, 0.0, 0.0), 1.0
    ta = hy.taylor_adaptive(events.system(sc, lay), st, tol=1e-15)
    ta.propagate_until(9.0)
    w = np.sqrt(3.0) * 9.0
    lam = np.log(np.linalg.norm(ta.state[lay.tangent : lay.tangent + 4]))
    assert abs(lam - 0.5 * np.log(np.cos(w) ** 2 + 3 * np.sin(w) ** 2)) <= 1e-12


@pytest.mark.parametrize(
    "kw",
    [
        {"gamma": 0.0},
        {"gamma": 0.01},  # the no-return rule: Λ at the last outward r_esc crossing
        {"gamma": 0.01, "sections": SectionWindow(), "r_far": 10.0},  # the generic handlers
    ],
    ids=["conservative", "no-return", "sections"],
)
def test_log_stretch_does_not_depend_on_chunk_or_batch_size(kw):
    sc = Scene(n=120, seed=5, energy=0.3, r_esc=1.03, t_max=20.0, tangent=True, **kw)
    ics = region_ics(sc, 0, sc.n)
    ids = np.arange(sc.n, dtype=np.int64)
    whole = run_chunk(sc, ics, ids).lifetimes
    out = whole["outcome"]
    assert (out == CENSORED).sum() > 2 and (out == ESCAPED).sum() > 40
    for size, b in ((1, None), (50, 4)):
        parts = [run_chunk(sc, ics[a : a + size], ids[a : a + size], batch_size=b) for a in range(0, sc.n, size)]
        for col in ("t_end", "log_stretch", "outcome"):
            v = np.concatenate([p.lifetimes[col] for p in parts])
            assert v.tobytes() == whole[col].tobytes(), (size, col)


def test_the_reference_driver_gives_the_engines_log_stretch():
    sc = Scene(n=6, seed=2, energy=0.22, t_max=30.0, tangent=True)
    ics = region_ics(sc, 0, sc.n)
    lt = run_chunk(sc, ics, np.arange(sc.n)).lifetimes
    for k in range(sc.n):
        o = simulate_orbit(sc, ics[k], fp_type=np.longdouble)
        assert o.outcome == lt["outcome"][k]
        assert abs(o.log_stretch - lt["log_stretch"][k]) <= 1e-9 * max(1.0, np.exp(o.log_stretch))


_TABLES = """
import hashlib
import numpy as np
from hhscatter.integrate.engine import run_chunk
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene, SectionWindow
for kw in ({}, {"gamma": 0.01, "sections": SectionWindow()}):
    sc = Scene(n=40, seed=1, energy=0.25, t_max=50.0, **kw)
    tables = run_chunk(sc, region_ics(sc, 0, sc.n), np.arange(sc.n)).tables()
    h = hashlib.sha256()
    for name in sorted(tables):
        for col in sorted(tables[name]):
            h.update(name.encode() + col.encode() + np.ascontiguousarray(tables[name][col]).tobytes())
    print(sc.result_hash(), h.hexdigest())
"""


def test_scenes_without_tangent_keep_the_hashes_and_tables_of_the_code_before_the_option(tmp_path):
    old = code_at(BASE, tmp_path / "old")

    def run(root):
        env = {**os.environ, "PYTHONPATH": str(root)}
        r = subprocess.run([sys.executable, "-c", _TABLES], cwd=tmp_path, env=env, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr[-2000:]
        return r.stdout

    before, after = run(old), run(ROOT)
    assert len(before.splitlines()) == 2 and after == before


def test_the_option_is_left_out_of_the_identity_at_its_default(tmp_path):
    sc = Scene(n=40, seed=1, energy=0.25, t_max=50.0, chunk_size=20)
    assert "tangent" not in sc.to_dict()
    assert sc.replace(tangent=False).result_hash() == sc.result_hash()
    assert sc.replace(tangent=True).result_hash() != sc.result_hash()
    assert "log_stretch" not in run_chunk(sc, region_ics(sc, 0, sc.n), np.arange(sc.n)).lifetimes
    simulate(sc, tmp_path / "bare", workers=1, progress=False)
    simulate(sc.replace(tangent=True), tmp_path / "tan", workers=1, progress=False)
    a, b = read_lifetimes(tmp_path / "bare"), read_lifetimes(tmp_path / "tan")
    assert "log_stretch" not in a.columns and "log_stretch" in b.columns
    assert (b["log_stretch"] > 0).mean() > 0.8
    assert a["outcome"].astype(str).tolist() == b["outcome"].astype(str).tolist()
    for col in ("t_end", "x0", "e_end"):  # the same orbits: δq never sets a step
        assert a[col].to_numpy().tobytes() == b[col].to_numpy().tobytes(), col


def test_a_tangent_run_of_selected_orbits_follows_the_same_orbits_as_the_run_that_selected_them(tmp_path):
    """Above E_c (chaotic scattering): the long-lived orbits of a run with sections, run again from their
    initial conditions with the tangent dynamics and the same sections, end at the same times, bit for bit, with
    the same section points (a chaotic orbit shifted by one rounding would be another orbit within ~35/λ)."""
    sc = Scene(n=400, seed=7, energy=1.32 / 6.0, t_max=120.0, sections=SectionWindow(t_from=0.0))
    simulate(sc, tmp_path / "main", workers=1, progress=False)
    lt = read_lifetimes(tmp_path / "main")
    sel = lt[(lt["outcome"].astype(str) == "escaped") & (lt["t_end"] > 40.0)].sort_values("traj_id")
    assert len(sel) >= 10
    sel.rename(columns={"x0": "x", "y0": "y", "px0": "px", "py0": "py"})[["traj_id", "x", "y", "px", "py"]].to_parquet(
        tmp_path / "ics.parquet"
    )
    again = Scene(energy=None, n=len(sel), ics=str(tmp_path / "ics.parquet"), t_max=sc.t_max, r_esc=sc.r_esc,
                  sections=sc.sections, tangent=True)  # fmt: skip
    simulate(again, tmp_path / "tan", workers=1, progress=False)
    b = read_lifetimes(tmp_path / "tan").sort_values("traj_id")
    assert b["traj_id"].tolist() == sel["traj_id"].tolist()
    assert b["t_end"].to_numpy().tobytes() == sel["t_end"].to_numpy().tobytes()
    assert (b["log_stretch"] / b["t_end"]).median() > 0.05
    s0, s1 = (read_sections(tmp_path / k).sort_values(["traj_id", "t"]) for k in ("main", "tan"))
    s0 = s0[s0["traj_id"].isin(sel["traj_id"])]
    assert len(s0) > 100 and s0[["t", "x", "y"]].to_numpy().tobytes() == s1[["t", "x", "y"]].to_numpy().tobytes()


@pytest.mark.parametrize(
    "kw, key",
    [
        ({"snapshots": (0.0, 1.0)}, "snapshots"),
        ({"sections": SectionWindow(t_from=5.0)}, "sections.t_from"),
        ({"tangent": 1}, "tangent must be true or false"),
    ],
)
def test_tangent_is_refused_where_it_is_not_available(kw, key):
    kw = {"tangent": True, **kw}
    with pytest.raises(ConfigError, match=key):
        Scene(energy=0.2, n=10, **kw)


def test_orbits_redone_on_the_reference_driver_and_escaped_at_the_start_keep_their_log_stretch():
    from hhscatter.integrate.rerun import _redo_on_reference

    scene = Scene(n=6, seed=3, energy=0.22, t_max=30.0, tangent=True)
    sc, ics, ids = plan_of(scene), region_ics(scene, 0, scene.n), np.arange(scene.n, dtype=np.int64)
    res = run_chunk(sc, ics, ids)
    again = _redo_on_reference(sc, run_chunk(sc, ics, ids), ics, ids, np.array([1, 4]))
    a, b = res.lifetimes["log_stretch"], again.lifetimes["log_stretch"]
    assert np.array_equal(np.delete(a, [1, 4]), np.delete(b, [1, 4]))
    assert np.allclose(a[[1, 4]], b[[1, 4]], rtol=0, atol=1e-9 * np.exp(np.abs(a[[1, 4]]).max()))
    assert not np.array_equal(a[[1, 4]], b[[1, 4]])  # (long double: the redone rows are new numbers)
    outside = np.vstack([ics[:2], [[1.2, 1.2, 0.0, 0.1]]])  # the third starts beyond r_esc: escaped at t = 0
    lt = run_chunk(sc, outside, np.arange(3)).lifetimes
    assert lt["t_end"][2] == 0.0 and lt["log_stretch"][2] == 0.0
    assert np.array_equal(lt["log_stretch"][:2], a[:2])


def test_a_log_stretch_beyond_its_bound_is_counted_and_warned_of():
    """Two confined orbits at E = 0.16 < E_c (x = 0, p_x = 0.25): y = 0.45 in the chaotic sea (λ ≈ 0.13) passes
    Λ = 600 before t = 5000, y = −0.25 on an invariant torus (Λ grows like ln t) does not; the chunk counts the
    first alone and warns of it."""
    e, px0 = 0.16, 0.25
    ics = np.array([[0.0, y, px0, np.sqrt(2 * (e - y * y / 2 + y**3 / 3 - px0 * px0 / 2))] for y in (0.45, -0.25)])
    sc = Scene(energy=0.17, n=2, t_max=5000.0, tangent=True)
    with pytest.warns(events.TangentStretchWarning, match="1 of 2 orbit"):
        res = run_chunk(sc, ics, np.arange(2))
    lam = res.lifetimes["log_stretch"]
    assert list(res.lifetimes["outcome"]) == [CENSORED, CENSORED]
    assert lam[0] > events.MAX_LOG_STRETCH > 100.0 > lam[1], lam
    assert res.tangent_beyond == 1


def test_a_resumed_run_counts_the_log_stretches_beyond_its_bound_in_the_chunks_it_keeps(tmp_path):
    """Three chunks, each of the two confined orbits above (one passes Λ = 600, one does not). The run is then
    stopped after its first chunk as an interruption leaves it (the other chunks' parts not written, scene.json
    without the closing counts) and resumed: the resumed run's total of orbits beyond the bound, in its summary and
    its scene.json, is the uninterrupted run's, 3, the kept chunk's orbit included."""
    e, px0 = 0.16, 0.25
    rows = [[0.0, y, px0, np.sqrt(2 * (e - y * y / 2 + y**3 / 3 - px0 * px0 / 2))] for y in (0.45, -0.25)] * 3
    table = tmp_path / "ics.csv"
    table.write_text("x,y,px,py\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in rows) + "\n")
    sc = Scene(energy=None, n=6, ics=str(table), t_max=5000.0, tangent=True, chunk_size=2)
    out = tmp_path / "run"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", events.TangentStretchWarning)
        whole = simulate(sc, out, workers=1, progress=False)
        for part in out.glob("*/part-00000[12].parquet"):
            part.unlink()
        doc = json.loads((out / "scene.json").read_text())
        for key in ("tangent_beyond", "event_failures"):
            doc.pop(key, None)
        (out / "scene.json").write_text(json.dumps(doc))
        resumed = simulate(sc, out, workers=1, resume=True, progress=False)
    assert whole.tangent_beyond == 3  # the chaotic orbit of each chunk
    assert (resumed.chunks_skipped, resumed.chunks_done) == (1, 2)
    assert resumed.tangent_beyond == whole.tangent_beyond
    assert json.loads((out / "scene.json").read_text())["tangent_beyond"] == 3
    assert "3 orbit(s) with a log-stretch" in resumed.line()
