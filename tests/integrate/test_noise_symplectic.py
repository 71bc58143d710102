"""The compiled noise flow (hhscatter.integrate.noise_symplectic): its random numbers, determinism, the stationary
energy against the Boltzmann closed form, the escape rate against the Taylor flow, the escape time against an
independent integrator, and the scene key that selects it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats
from scipy.integrate import solve_ivp

from hhscatter.analysis.noise import thermal_rate
from hhscatter.errors import ConfigError
from hhscatter.integrate.engine import CENSORED, ESCAPED, run_chunk
from hhscatter.integrate.noise_symplectic import _philox, philox4x32, symplectic_escapes
from hhscatter.integrate.plan import plan_of
from hhscatter.model import HenonHeiles
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Noise, Scene, scene_from_dict

# Random123 (D. E. Shaw Research), tests/kat_vectors, "philox4x32 10": counter, key, output
KAT = [
    ((0, 0, 0, 0), (0, 0), (0x6627E8D5, 0xE169C58D, 0xBC57AC4C, 0x9B00DBD8)),
    ((0xFFFFFFFF,) * 4, (0xFFFFFFFF,) * 2, (0x408F276D, 0x41C83B0E, 0xA20BC7C6, 0x6D5451FD)),
    (
        (0x243F6A88, 0x85A308D3, 0x13198A2E, 0x03707344),
        (0xA4093822, 0x299F31D0),
        (0xD16CFE09, 0x94FDCCEB, 0x5001E420, 0x24126EA1),
    ),
]


@pytest.mark.parametrize("counter, key, expected", KAT)
def test_philox_matches_the_random123_known_answers(counter, key, expected):
    assert philox4x32(counter, key) == expected


def test_the_kick_normals_are_independent_standard_normals():
    _, normals = _philox()
    u = np.uint64
    z = np.array([normals(k, u(t), u(0), u(12345), u(678)) for t in range(4) for k in range(5000)])
    flat = z.ravel()
    assert stats.kstest(flat, "norm").pvalue > 1e-3
    assert abs(flat.mean()) < 4 / math.sqrt(flat.size) and abs(flat.var() - 1) < 4 * math.sqrt(2 / flat.size)
    c = np.corrcoef(z.T)  # the four normals of one counter are uncorrelated
    assert np.abs(c - np.eye(4)).max() < 4 / math.sqrt(len(z))


def _scene(**kw):
    base = dict(energy=0.16, n=400, gamma=1.0, t_max=40.0, seed=4, noise=Noise(temperature=1 / 12, flow="symplectic"))
    return Scene(**{**base, **kw})


def _bitwise(a: dict, b: dict, what):
    for col, v in a.items():
        assert v.dtype == b[col].dtype and v.tobytes() == b[col].tobytes(), (what, col)


@pytest.mark.parametrize(
    "noise, gamma",
    [(Noise(temperature=1 / 12, flow="symplectic"), 1.0), (Noise(sigma=0.04, flow="symplectic"), 0.0)],
    ids=["heat-bath", "no-drag"],
)
def test_tables_do_not_depend_on_chunk_or_batch_size(noise, gamma):
    sc = _scene(gamma=gamma, noise=noise)
    ics = region_ics(sc, 0, sc.n)
    ids = np.arange(sc.n, dtype=np.int64)
    whole = run_chunk(sc, ics, ids).lifetimes
    assert (whole["outcome"] == ESCAPED).sum() > 30 and (whole["outcome"] == CENSORED).sum() > 30
    for size, batch in ((37, 4), (128, 16)):
        parts = [
            run_chunk(sc, ics[a : a + size], ids[a : a + size], batch_size=batch).lifetimes
            for a in range(0, sc.n, size)
        ]
        _bitwise(whole, {c: np.concatenate([p[c] for p in parts]) for c in parts[0]}, (size, batch))


def test_runs_are_byte_identical_whatever_the_workers(tmp_path):
    from hhscatter.data.read import read_lifetimes
    from hhscatter.run.runner import simulate

    sc = _scene(n=300, chunk_size=70)
    simulate(sc, tmp_path / "one", workers=1, progress=False)
    simulate(sc.replace(chunk_size=32), tmp_path / "two", workers=2, progress=False)
    a, b = (read_lifetimes(tmp_path / d).sort_values("traj_id").reset_index(drop=True) for d in ("one", "two"))
    assert set(a["outcome"].astype(str)) == {"escaped", "censored"}
    assert a["outcome"].astype(str).tolist() == b["outcome"].astype(str).tolist()
    for col in ("t_end", "e_end", "exit_channel"):
        assert a[col].to_numpy().tobytes() == b[col].to_numpy().tobytes(), col


@pytest.mark.parametrize(
    "gamma, noise",
    [(1.0, Noise(temperature=1 / 12, flow="symplectic")), (0.0, Noise(sigma=0.04, flow="symplectic"))],
    ids=["heat-bath", "no-drag"],
)
def test_a_run_to_an_earlier_time_is_the_longer_runs_beginning(gamma, noise):
    """The same scene to t_max = 20 and 40 (the same kick interval): escapes before 20 are bit-identical, and the
    orbits inside at 20 are those of the longer run that were still inside then (a survivor's energy at 20 is read
    from the shorter run)."""
    sc = _scene(gamma=gamma, noise=noise)
    ics = region_ics(sc, 0, sc.n)
    ids = np.arange(sc.n, dtype=np.int64)
    short, long = (run_chunk(sc.replace(t_max=t), ics, ids).lifetimes for t in (20.0, 40.0))
    esc = short["outcome"] == ESCAPED
    assert 30 < esc.sum() < sc.n - 30
    assert short["t_end"][esc].tobytes() == long["t_end"][esc].tobytes()
    assert short["e_end"][esc].tobytes() == long["e_end"][esc].tobytes()
    assert np.all(short["outcome"][~esc] == CENSORED) and np.all(long["t_end"][~esc] > 20.0)


def test_an_orbits_kicks_depend_on_seed_and_traj_id_only():
    sc = _scene(n=3)
    ics = np.repeat(region_ics(sc, 0, 1), 3, axis=0)
    one = run_chunk(sc, ics, np.array([5, 6, 5])).lifetimes["e_end"]
    assert one[0] == one[2] and one[0] != one[1]
    other = run_chunk(sc.replace(seed=5), ics, np.array([5, 6, 5])).lifetimes["e_end"]
    assert other[0] != one[0]


def _boltzmann_mean_v(model, T, r_max=1.0, nr=4000, nth=720):
    r = np.linspace(0.0, r_max, nr)
    th = np.linspace(0.0, 2 * np.pi, nth, endpoint=False)
    R, TH = np.meshgrid(r, th, indexing="ij")
    V = model.potential(R * np.cos(TH), R * np.sin(TH))
    w = np.exp(-V / T) * R
    return float((V * w).sum() / w.sum())


@pytest.mark.parametrize("kick", [None, 0.5], ids=["default-kick", "largest-kick"])
def test_the_stationary_energy_is_boltzmanns(kick):
    """A deep well (ΔE/T = 10): the end states of 20 000 orbits after t = 30 ≫ 1/γ sample the stationary density;
    ⟨K⟩ = T (two degrees of freedom) and ⟨E⟩ = T + ⟨V⟩ with ⟨V⟩ the Boltzmann average (quadrature), each within
    4σ; a 3 % colder bath is rejected (the test has power)."""
    T, n = 1 / 60, 20000
    sc = Scene(
        energy=0.01, n=n, gamma=1.0, t_max=30.0, seed=2, noise=Noise(temperature=T, kick=kick, flow="symplectic")
    )
    lt = run_chunk(sc, region_ics(sc, 0, n), np.arange(n)).lifetimes
    kept = lt["outcome"] == CENSORED
    assert (~kept).sum() <= 10
    E = lt["e_end"][kept]
    expected = T + _boltzmann_mean_v(sc.model, T)
    sigma = E.std() / math.sqrt(E.size)
    assert abs(E.mean() - expected) < 4 * sigma, (E.mean(), expected, sigma)
    assert abs(E.mean() - 0.97 * expected) > 4 * sigma


def test_the_escape_rate_agrees_with_the_taylor_flow():
    """γ = 1, ΔE/T = 3 from the well, rate on [20, 150]: the compiled flow (30 000 orbits, largest kick) against
    the Taylor flow (3000 orbits at the kick 0.5 and tolerance 1e-9 of the work–precision benchmark) within 3σ."""
    T = (1 / 6) / 3

    def rate(flow, n):
        sc = Scene(
            energy=0.05, n=n, gamma=1.0, t_max=150.0, seed=11, tol=1e-9, region="disk", radius=0.5,
            noise=Noise(temperature=T, kick=0.5, flow=flow),
        )  # fmt: skip
        lt = run_chunk(sc, region_ics(sc, 0, n), np.arange(n)).lifetimes
        return thermal_rate(lt["t_end"], lt["outcome"] == ESCAPED, 20.0, 150.0)

    a, b = rate("symplectic", 30000), rate("taylor", 3000)
    assert a.n_events > 15000 and b.n_events > 1500
    assert abs(a.rate - b.rate) < 3 * math.hypot(a.rate_err, b.rate_err), (a.rate, b.rate)


def _dop853_escape(model, state, r_esc):
    def rhs(t, s):
        fx, fy = model.force(s[0], s[1])
        return [s[2], s[3], fx, fy]

    def out(t, s):
        return s[0] ** 2 + s[1] ** 2 - r_esc**2

    out.terminal, out.direction = True, 1
    sol = solve_ivp(rhs, (0.0, 10.0), state, method="DOP853", rtol=1e-13, atol=1e-13, events=out)
    return (sol.t_events[0][0], sol.y_events[0][0]) if len(sol.t_events[0]) else (math.inf, None)


def test_escape_times_and_states_converge_at_fourth_order_to_an_independent_integrator():
    """Without noise and drag the flow is the symplectic step alone: the escape time and state (at the root of the
    Hermite interpolant) against SciPy's DOP853 at tolerance 1e-13, for orbits above E_c that leave before t = 8;
    the error falls ≥ 8× when h halves (fourth order: 16×) and the end state lies on r = r_esc."""
    model, r_esc = HenonHeiles(), 1.5
    rng = np.random.default_rng(0)
    ics = []
    for _ in range(40):
        x, y = rng.uniform(-0.3, 0.3, 2)
        th = rng.uniform(0, 2 * np.pi)
        p = math.sqrt(2 * (0.22 - float(model.potential(np.array(x), np.array(y)))))
        ics.append([x, y, p * math.cos(th), p * math.sin(th)])
    ics = np.array(ics)
    ref = [_dop853_escape(model, s, r_esc) for s in ics]
    fast = np.array([t < 8.0 for t, _ in ref])
    assert fast.sum() >= 10
    errors = {}
    for h in (0.1, 0.05):
        o, t, st = symplectic_escapes(
            model, ics, np.arange(len(ics)), seed=1, gamma=0.0, sigma=0.0, h=h, n_kicks=round(50 / h), r_esc=r_esc
        )
        assert (o[fast] == ESCAPED).all()
        assert np.allclose(np.hypot(st[fast, 0], st[fast, 1]), r_esc, rtol=0, atol=1e-12)
        errors[h] = max(max(abs(t[i] - ref[i][0]), np.abs(st[i] - ref[i][1]).max()) for i in np.flatnonzero(fast))
    assert errors[0.1] < 2e-3
    assert errors[0.1] / errors[0.05] > 8, errors


def test_the_flow_key_selects_the_scheduler_and_is_checked():
    assert plan_of(_scene()).scheduler == "noise_symplectic"
    assert plan_of(_scene(noise=Noise(temperature=1 / 12))).scheduler == "noise"
    # the default spelled out is the same scene (and scene hash) as without it
    taylor = _scene(noise=Noise(temperature=1 / 12, flow="taylor"))
    assert taylor.to_dict() == _scene(noise=Noise(temperature=1 / 12)).to_dict()
    assert _scene().to_dict()["noise"] == {"temperature": 1 / 12, "flow": "symplectic"}
    with pytest.raises(ConfigError, match=r"noise\.flow must be one of \['taylor', 'symplectic'\], got 'rk4'"):
        Noise(temperature=1 / 12, flow="rk4")
    d = _scene().to_dict()
    assert scene_from_dict(d) == _scene()


def test_a_graze_between_two_step_ends_is_an_escape():
    """An orbit on the y axis (where Hénon–Heiles keeps it) whose turning point y = 0.301 lies in the middle of a
    step of h = 0.5: both step ends are inside r_esc = 0.3, the path is not; the escape is found at the crossing
    of SciPy's DOP853 (tolerance 1e-13) to the interpolant's accuracy."""
    model, r_esc, h = HenonHeiles(), 0.3, 0.5

    def rhs(t, s):
        fx, fy = model.force(s[0], s[1])
        return [s[2], s[3], fx, fy]

    turn = np.array([0.0, 0.301, 0.0, 0.0])
    start = solve_ivp(rhs, (0.0, -0.5 * h), turn, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    end = solve_ivp(rhs, (0.0, 0.5 * h), turn, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    assert math.hypot(*start[:2]) < r_esc and math.hypot(*end[:2]) < r_esc
    t_ref, _ = _dop853_escape(model, start, r_esc)
    o, t, st = symplectic_escapes(model, start[None, :], [0], seed=1, gamma=0.0, sigma=0.0, h=h, n_kicks=1, r_esc=r_esc)
    assert o[0] == ESCAPED and abs(t[0] - t_ref) < 1e-3, (t[0], t_ref)
    assert math.hypot(st[0, 0], st[0, 1]) == pytest.approx(r_esc, abs=1e-12)
