"""The notebook API: hhscatter.survival / escape_rates / plot helpers on lifetimes DataFrames, and the
"Analyze your own run" page, whose code is executed here exactly as printed."""

import importlib.metadata
import math
import os
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import hhscatter
from hhscatter.analysis.survival.fits import survival_curve

DOCS = Path(__file__).resolve().parents[1] / "docs"
EPS = np.finfo(float).eps


def _frame(points, n=20_000, seed=0, energy_column=True):
    """Synthetic lifetimes: exponential escape at rate κ per (energy, γ, κ); e0 scattered in the last bits."""
    rng = np.random.default_rng(seed)
    parts = []
    for energy, gamma, kappa in points:
        t = rng.exponential(1 / kappa, n) + 2.0  # an irregular start would be here; pure delay is enough
        df = pd.DataFrame(
            {
                "traj_id": np.arange(n),
                "e0": energy * (1 + EPS * rng.integers(-4, 5, n)),
                "gamma": gamma,
                "outcome": np.where(t > 60, "censored", "escaped"),
                "t_end": np.minimum(t, 60.0),
            }
        )
        if energy_column:
            df["energy"] = energy
        parts.append(df)
    return pd.concat(parts, ignore_index=True)


def test_public_names_are_listed_and_version_comes_from_metadata():
    for name in ("survival", "escape_rates", "plot_survival", "plot_escape_rates", "Grid", "read_lifetimes"):
        assert name in hhscatter.__all__ and name in dir(hhscatter), name
    for name in hhscatter.__all__:
        assert getattr(hhscatter, name) is not None
    assert hhscatter.__version__ == importlib.metadata.version("hhscatter")
    assert "version" not in dir(hhscatter)  # no helper names leak into the namespace


def test_every_top_level_name_points_at_its_defining_module_and_the_docstring_lists_it():
    """hhscatter._EXPORTS maps each lazy name to the module that defines it (or the package that exports it), and
    the package docstring names every one of them, nothing else."""
    for name, where in hhscatter._EXPORTS.items():
        defined_in = getattr(hhscatter, name).__module__
        assert defined_in == f"hhscatter.{where}" or defined_in.startswith(f"hhscatter.{where}."), (name, where)
    listed = set(re.findall(r":(?:class|func):`(\w+)`", hhscatter.__doc__))
    assert listed == set(hhscatter._EXPORTS)


def test_points_are_grouped_by_energy_never_by_e0():
    from hhscatter.api import split_points

    lt = _frame([(0.27, 0.0, 0.15), (0.3, 0.0, 0.2), (0.3, 0.01, 0.1)], n=500)
    assert lt.groupby(["e0", "gamma"]).ngroups > 3  # what the old error message suggested
    keys = [k for k, _ in split_points(lt)]
    assert keys == [(0.27, 0.0), (0.3, 0.0), (0.3, 0.01)]
    # plain runs concatenated (no energy column): e0 clustered within 1e-9
    assert [k for k, _ in split_points(lt.drop(columns="energy"))] == keys
    # a run from an IC table (e0 varies continuously): one ensemble per γ, energy unknown
    ics = lt[lt.gamma == 0].drop(columns="energy").assign(e0=np.linspace(0.2, 0.4, 1000), traj_id=np.arange(1000))
    ((key, df),) = split_points(ics)
    assert math.isnan(key[0]) and key[1] == 0.0 and len(df) == 1000


def test_survival_gives_one_kaplan_meier_curve_per_point():
    lt = _frame([(0.27, 0.0, 0.15), (0.3, 0.01, 0.1)], n=2000)
    curves = hhscatter.survival(lt)
    assert len(curves) == 2 and curves.n == {(0.27, 0.0): 2000, (0.3, 0.01): 2000}
    one = lt[lt.energy == 0.3]
    ref = survival_curve(one["t_end"].to_numpy(), (one["outcome"] != "censored").to_numpy())
    got = curves[(0.3, 0.01)]
    assert np.array_equal(got.t, ref.t) and np.array_equal(got.P, ref.P) and got is curves[0.3]
    df = curves.to_frame()
    assert list(df.columns) == ["energy", "gamma", "n", "t", "P", "P_err"]
    assert df.groupby(["energy", "gamma"]).size().tolist() == [len(curves[0.27].t), len(ref.t)]
    grid = hhscatter.survival(lt, t_grid=np.linspace(0, 50, 11)).to_frame()
    assert len(grid) == 22 and (grid.loc[grid.t == 0, "P"] == 1).all()


def test_escape_rates_per_point_and_no_kappa_for_dissipative_points():
    lt = _frame([(0.27, 0.0, 0.15), (0.3, 0.0, 0.25), (0.3, 0.01, 0.1)])
    with pytest.warns(UserWarning, match=r"not fitted for the dissipative point\(s\) E0=0.3, γ=0.01"):
        rates = hhscatter.escape_rates(lt, detect_tail=False)
    df = rates.to_frame()
    assert list(df[["energy", "gamma"]].itertuples(index=False, name=None)) == [(0.27, 0.0), (0.3, 0.0), (0.3, 0.01)]
    for kappa, row in zip((0.15, 0.25), df.iloc[:2].itertuples()):
        assert abs(row.kappa - kappa) < 4 * row.kappa_err and row.kappa_err < 0.05 * kappa
        assert row.tau0 >= 0 and len(row.windows) == 4 and row.note == "" and row.n == 20_000
    diss = df.iloc[2]
    assert math.isnan(diss.kappa) and "dissipative" in diss.note
    assert set(rates.results) == {(0.27, 0.0), (0.3, 0.0)}


def test_single_ensemble_escape_rate_refuses_a_dissipative_run():
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes
    from hhscatter.analysis.survival.fits import lifetimes_to_arrays

    lt = _frame([(0.3, 0.01, 0.1)], n=5000)
    with pytest.raises(ValueError, match="dissipative"):
        escape_rate_from_lifetimes(lt)
    with pytest.warns(UserWarning, match="dissipative"):
        escape_rate_from_lifetimes(lt, allow_dissipative=True, detect_tail=False)
    two = _frame([(0.27, 0.0, 0.15), (0.3, 0.0, 0.2)], n=100)
    with pytest.raises(ValueError, match=r"hhscatter.survival.*groupby\(\['energy', 'gamma'\]\)"):
        lifetimes_to_arrays(two)


def test_plot_helpers_draw_on_the_given_axes_and_never_touch_the_backend(monkeypatch):
    import matplotlib
    from matplotlib.figure import Figure

    def forbidden(*a, **k):
        raise AssertionError("matplotlib.use called")

    monkeypatch.setattr(matplotlib, "use", forbidden)
    backend = matplotlib.get_backend()
    lt = _frame([(0.27, 0.0, 0.15), (0.3, 0.0, 0.25)], n=3000)
    ax = Figure().subplots()
    assert hhscatter.plot_survival(hhscatter.survival(lt), ax=ax) is ax
    assert len(ax.get_lines()) == 2 and ax.get_yscale() == "log"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["E0=0.27, γ=0 (N=3000)", "E0=0.3, γ=0 (N=3000)"]
    ax2 = Figure().subplots()
    rates = hhscatter.escape_rates(lt, detect_tail=False)
    assert rates.plot(ax=ax2) is ax2 and len(ax2.containers) == 1  # one errorbar series (γ = 0)
    assert matplotlib.get_backend() == backend
    with pytest.raises(ValueError, match="1 labels for 2 curves"):
        hhscatter.plot_survival(hhscatter.survival(lt), ax=ax, labels=["x"])


def test_each_concept_has_one_top_level_function_with_a_frame_and_a_plot():
    from matplotlib.figure import Figure

    for name in (
        "kappa_cmeasure",
        "transition_times",
        "energy_decay",
        "cmeasure_points",
        "cmeasure_distances",
        "basin_measures",
    ):
        fn = getattr(hhscatter, name)
        assert name in hhscatter.__all__ and fn.__module__.startswith("hhscatter.api."), name
        doc = fn.__doc__
        assert all(s in doc for s in ("Parameters\n", "Returns\n", "Examples\n", ">>> ")), name
    # one synthetic frame per concept, drawn on a given axes
    lt = _frame([(0.3, 0.0, 0.2)], n=2000)
    res = hhscatter.transition_times(pd.concat([lt, lt.assign(gamma=0.01)]))
    assert res.plot(ax=Figure().subplots()).get_xscale() == "log"


def _settling_frame():
    """γ = 0: escapes at rate 0.2 after t = 5; γ = 0.01: the same orbits, those alive at t = 20 then leave at rate
    1/40 and settle (rather than escape) beyond t = 30. τ1 (α = 2) is where P_γ/P_0 = 2, in closed form."""
    rng = np.random.default_rng(3)
    t0 = 5 + rng.exponential(5.0, 40_000)
    tg = np.where(t0 > 20, 20 + rng.exponential(40.0, t0.size), t0)
    mk = lambda g, t, out: pd.DataFrame(
        {
            "energy": 0.3,
            "gamma": g,
            "t_end": t,
            "outcome": out,  # noqa: E731
            "traj_id": np.arange(t.size),
        }
    )
    return pd.concat([mk(0.0, t0, "escaped"), mk(0.01, tg, np.where(tg > 30, "settled", "escaped"))])


def test_transition_times_against_closed_forms():
    lt = _settling_frame()
    row = hhscatter.transition_times(lt).to_frame().iloc[0]
    g = lt[lt.gamma == 0.01]
    assert row.tau2 == g.loc[g.outcome == "settled", "t_end"].min()  # the earliest settling time, exactly
    assert row.tau2_lo <= row.tau2 <= row.tau2_hi
    # P_0 = e^{-(t-5)/5}; for t > 20 P_γ = e^{-3} e^{-(t-20)/40}; P_γ = 2 P_0 where (t-5)/5 - (t-20)/40 = 3 + ln 2
    t1 = (3.5 + math.log(2)) / (1 / 5 - 1 / 40)
    assert abs(row.tau1 - t1) < 0.6, (row.tau1, t1)
    lone = hhscatter.transition_times(lt[lt.gamma > 0].assign(energy=0.35)).to_frame().iloc[0]
    assert math.isnan(lone.tau1) and "no conservative" in lone.note


def test_energy_decay_per_grid_point_and_plain_runs_need_e0_and_gamma():
    t = np.repeat(np.arange(0.0, 101.0, 5.0), 20)
    rows = [
        pd.DataFrame({"traj_id": 0, "t": t, "energy": e0 * np.exp(-mu * g * t), "point_energy": e0, "point_gamma": g})
        for e0, g, mu in ((0.3, 0.01, 0.9), (0.3, 0.02, 0.8), (0.4, 0.0, 0))
    ]
    res = hhscatter.energy_decay(pd.concat(rows), window=(0, 100))
    fr = res.to_frame()
    assert list(zip(fr.energy, fr.gamma)) == [(0.3, 0.01), (0.3, 0.02)]  # γ = 0: a curve, no μ
    assert np.allclose(fr.mu, [0.9, 0.8], atol=1e-9) and len(res.curves) == 3
    assert set(res.curves_frame().energy) == {0.3, 0.4}
    with pytest.raises(ValueError, match="pass energy= and gamma="):
        hhscatter.energy_decay(rows[0].drop(columns=["point_energy", "point_gamma"]))


def test_cmeasure_points_and_distances_per_point():
    sec = pd.DataFrame(
        {
            "traj_id": [1, 1, 1, 2, 2, 3],
            "t": [5.0, 25.0, 28.0, 22.0, 40.0, 50.0],
            "x": [0.0, 0.1, 0.2, 0.3, 0.4, 0.5],
            "y": 0.0,
            "energy": [0.3, 0.3, 0.3, 0.29, 0.28, 0.2],
            "point_energy": 0.3,
            "point_gamma": 0.01,
        }
    )
    every = hhscatter.cmeasure_points(sec, t_from=20.0, t_to=45.0)
    assert every[(0.3, 0.01)]["x"].tolist() == [0.1, 0.2, 0.3, 0.4]
    band = hhscatter.cmeasure_points(sec, t_from=20.0, first_only=True, e_min=0.25)
    assert band[(0.3, 0.01)]["x"].tolist() == [0.1, 0.3]  # orbit 3's first crossing is outside the band
    rng = np.random.default_rng(2)
    far = pd.DataFrame(rng.uniform(0, 1, (3000, 2)), columns=["x", "y"]).assign(
        t=30.0, traj_id=np.arange(3000), point_energy=0.3, point_gamma=0.05
    )
    ref = pd.DataFrame(rng.uniform(-1, 1, (3000, 2)), columns=["x", "y"])
    d = hhscatter.cmeasure_distances(hhscatter.cmeasure_points(far, t_from=0.0), ref, boxes=[0.5], n_splits=4)
    row = d.to_frame().iloc[0]
    # a quarter of the square against the whole square: total variation 3/4 (closed form), far above the noise
    assert abs(row.tv - 0.75) < 0.03 and row.tv_excess > 0.5


def test_basin_measures_maps_outcomes_to_cells():
    shape, cell = (4, 4), np.array([1, 2, 5, 6, 9, 10])  # 6 allowed cells, the rest forbidden
    lt = pd.DataFrame(
        {
            "traj_id": [5, 4, 3, 2, 1, 0],
            "gamma": 0.01,
            "e0": 0.3,
            "t_end": 1.0,
            "outcome": ["escaped", "settled", "censored", "escaped", "escaped", "escaped"],
            "exit_channel": pd.array([2, None, None, 1, 0, 0], dtype="Int8"),
        }
    )
    m = hhscatter.basin_measures(lt, cell, shape, boxes=[2], wada=False, extent=(-1, 1, -1, 1))
    lab = m.maps[(0.3, 0.01)]
    F = hhscatter.api
    want = np.full(16, F.OUTSIDE_BASIN)
    want[cell] = [0, 0, 1, F.TRAPPED_BASIN, F.SETTLED_BASIN, 2]
    assert (lab.ravel() == want).all()
    fr = m.to_frame()
    assert fr["share exit 0"].iloc[0] == pytest.approx(2 / 6) and fr["share settled"].iloc[0] == pytest.approx(1 / 6)
    with pytest.raises(ValueError, match="has no cell"):
        hhscatter.basin_measures(lt.assign(traj_id=lt.traj_id + 1), cell, shape)


def test_kappa_cmeasure_refuses_runs_whose_sections_do_not_hold_every_crossing(tmp_path):
    plain = hhscatter.Scene(energy=0.3, n=50, seed=1, t_max=50.0)
    hhscatter.simulate(plain, tmp_path / "none", overwrite=True, workers=1, progress=False)
    with pytest.raises(ValueError, match="recorded no sections"):
        hhscatter.kappa_cmeasure(tmp_path / "none")
    first = plain.replace(sections=hhscatter.SectionWindow(t_from=10.0, first_only=True))
    hhscatter.simulate(first, tmp_path / "first", overwrite=True, workers=1, progress=False)
    with pytest.raises(ValueError, match="needs every section crossing"):
        hhscatter.kappa_cmeasure(tmp_path / "first")


def _page_code(page: Path) -> str:
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S)
    assert len(blocks) >= 1, page
    return blocks[0]


def test_analyse_your_own_run_page_runs_as_printed(tmp_path):
    """The first python block of docs/analyse.md, saved as analyse.py and run as a script (the issue: without
    its ``if __name__ == "__main__":`` guard, spawn re-imported it and every worker failed)."""
    import subprocess
    import sys

    code = _page_code(DOCS / "analyse.md")
    assert len([ln for ln in code.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]) <= 12
    (tmp_path / "analyse.py").write_text(code)
    env = {**os.environ, "MPLBACKEND": "Agg"}  # the test's choice (headless); the page's code never sets one
    proc = subprocess.run(
        [sys.executable, "analyse.py"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600
    )
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr[-3000:]
    assert "dissipative" in proc.stderr  # the UserWarning naming the γ > 0 points
    rows = [ln.split() for ln in proc.stdout.splitlines() if re.match(r"^\d+\s+0\.", ln)]
    assert [(r[1], r[2], r[3]) for r in rows] == [
        ("0.27", "0.00", "10000"),
        ("0.27", "0.01", "10000"),
        ("0.30", "0.00", "10000"),
        ("0.30", "0.01", "10000"),
    ], proc.stdout
    kappa = {(r[1], r[2]): float(r[4]) for r in rows}
    assert math.isnan(kappa[("0.27", "0.01")]) and math.isnan(kappa[("0.30", "0.01")])
    # κ(E) grows with E (paper Fig. 2b): 0.27 → ~0.14, 0.30 → ~0.19
    assert 0.10 < kappa[("0.27", "0.00")] < kappa[("0.30", "0.00")] < 0.3
    assert (tmp_path / "runs" / "mine.png").stat().st_size > 10_000


def test_kappa_cmeasure_agrees_with_kappa_from_pt_on_a_real_run(tmp_path):
    """Two independent estimators of κ on one run (E = 0.3, 4·10⁴ orbits, ~3 s): the c-measure renewal equation on
    the section crossings in the late window, and the window fits of P(t). At 2·10⁵ orbits per energy they gave
    0.0956 ± 0.0014 / 0.185 ± 0.004 / 0.246 ± 0.005 against 0.0953 ± 0.0015 / 0.187 ± 0.002 / 0.246 ± 0.003 at
    E = 0.25 / 0.30 / 0.35 (the issue: 0.0974 / 0.181 / 0.235 against 0.0973 / 0.183 / 0.246)."""
    scene = hhscatter.Scene(
        energy=0.3, n=40_000, seed=7, t_max=3000.0, sections=hhscatter.SectionWindow(t_from=10.0, t_to=160.0)
    )
    hhscatter.simulate(scene, tmp_path / "run", overwrite=True, workers=1, progress=False)
    row = hhscatter.kappa_cmeasure(tmp_path / "run").to_frame().iloc[0]
    assert row.note == "" and row.n_undetermined == 0 and row.t_record_end == 160.0 and row.t_to == 120.0
    assert 0.15 < row.kappa_cm < 0.23 and row.kappa_cm_err < 0.02
    assert abs(row.kappa_cm - row.kappa_pt) < 2.5 * math.hypot(row.kappa_cm_err, row.kappa_pt_err)
    assert 0.3 < row.mu_exit < 0.5  # μ_c(𝓔): a third or more of the late crossings exit before the next one


def test_progress_goes_to_a_log_as_plain_lines_never_as_a_bar(tmp_path):
    """The API's default progress=True, with stderr a file (a log): plain lines, no carriage return, no tqdm."""
    import subprocess
    import sys

    code = (
        "import hhscatter\nif __name__ == '__main__':\n"
        "    hhscatter.simulate(hhscatter.Scene(energy=0.3, n=200, seed=1, t_max=50.0), 'run', workers=1)\n"
    )
    (tmp_path / "s.py").write_text(code)
    with open(tmp_path / "log.txt", "w") as log:
        subprocess.run([sys.executable, "s.py"], cwd=tmp_path, stderr=log, stdout=log, check=True, timeout=300)
    text = (tmp_path / "log.txt").read_text()
    assert "\r" not in text and "it/s" not in text and "orbit/s" not in text
    assert "200/200 orbits (100 %)" in text


def test_read_lifetimes_takes_a_list_of_runs(tmp_path):
    a = hhscatter.Scene(energy=0.27, n=300, seed=1, t_max=100.0)
    hhscatter.simulate(a, tmp_path / "a", workers=1, progress=False)
    hhscatter.simulate(hhscatter.Grid(a, energies=[0.3], gammas=[0.0, 0.01]), tmp_path / "g", workers=1, progress=False)
    both = hhscatter.read_lifetimes([tmp_path / "a", str(tmp_path / "g")])
    assert len(both) == 900 and list(both["run"].cat.categories) == [str(tmp_path / "a"), str(tmp_path / "g")]
    curves = hhscatter.survival(both)
    assert sorted(curves.curves) == [
        (0.27, 0.0, str(tmp_path / "a")),
        (0.3, 0.0, str(tmp_path / "g")),
        (0.3, 0.01, str(tmp_path / "g")),
    ]
    assert (
        all(n == 300 for n in curves.n.values())
        and curves[(0.3, 0.01)] is curves.curves[(0.3, 0.01, str(tmp_path / "g"))]
    )


def test_escape_rates_flags_a_trapped_population_instead_of_returning_its_plateau_silently():
    # 60 % of the orbits never leave (KAM tori), the rest at κ = 0.01: the window κ is the plateau's
    rng = np.random.default_rng(11)
    t = np.where(rng.random(20000) < 0.6, np.inf, rng.exponential(100.0, 20000))
    lt = pd.DataFrame(
        {"t_end": np.minimum(t, 800.0), "outcome": np.where(t < 800.0, "escaped", "censored"), "e0": 0.3, "gamma": 0.0}
    )
    row = hhscatter.escape_rates(lt, detect_tail=False).to_frame().iloc[0]
    assert row.status == "trapped" and "plateau" in row.note
    assert abs(row.p_inf - 0.6) < 0.03 and abs(row.kappa_inf - 0.01) < 0.001


def test_escape_rates_leaves_an_exponential_population_unflagged():
    t = np.random.default_rng(12).exponential(5.0, 20000)
    lt = pd.DataFrame({"t_end": t, "outcome": "escaped", "e0": 0.3, "gamma": 0.0})
    row = hhscatter.escape_rates(lt, detect_tail=False).to_frame().iloc[0]
    assert row.status == "exponential" and row.note == ""
