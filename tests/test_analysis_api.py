"""The notebook API: hhscatter.survival / escape_rates / plot helpers on lifetimes DataFrames, and the
"Analyse your own run" page, whose code is executed here exactly as printed."""
import importlib.metadata
import math
import os
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import hhscatter
from hhscatter.analysis.survival import survival_curve

DOCS = Path(__file__).resolve().parents[1] / "docs"
EPS = np.finfo(float).eps


def _frame(points, n=20_000, seed=0, energy_column=True):
    """Synthetic lifetimes: exponential escape at rate κ per (energy, γ, κ); e0 scattered in the last bits."""
    rng = np.random.default_rng(seed)
    parts = []
    for energy, gamma, kappa in points:
        t = rng.exponential(1 / kappa, n) + 2.0  # an irregular start would be here; pure delay is enough
        df = pd.DataFrame({"traj_id": np.arange(n), "e0": energy * (1 + EPS * rng.integers(-4, 5, n)),
                           "gamma": gamma, "outcome": np.where(t > 60, "censored", "escaped"),
                           "t_end": np.minimum(t, 60.0)})
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


def test_points_are_grouped_by_energy_never_by_e0():
    from hhscatter.analysis.frames import split_points

    lt = _frame([(0.27, 0.0, 0.15), (0.3, 0.0, 0.2), (0.3, 0.01, 0.1)], n=500)
    assert lt.groupby(["e0", "gamma"]).ngroups > 3  # what the old error message suggested
    keys = [k for k, _ in split_points(lt)]
    assert keys == [(0.27, 0.0), (0.3, 0.0), (0.3, 0.01)]
    # plain runs concatenated (no energy column): e0 clustered within 1e-9
    assert [k for k, _ in split_points(lt.drop(columns="energy"))] == keys
    # a run from an IC table (e0 varies continuously): one ensemble per γ, energy unknown
    ics = lt[lt.gamma == 0].drop(columns="energy").assign(e0=np.linspace(0.2, 0.4, 1000))
    (key, df), = split_points(ics)
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
    from hhscatter.analysis.escape_rate import escape_rate_from_lifetimes
    from hhscatter.analysis.survival import lifetimes_to_arrays

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
    proc = subprocess.run([sys.executable, "analyse.py"], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr[-3000:]
    assert "dissipative" in proc.stderr  # the UserWarning naming the γ > 0 points
    rows = [ln.split() for ln in proc.stdout.splitlines() if re.match(r"^\d+\s+0\.", ln)]
    assert [(r[1], r[2], r[3]) for r in rows] == [("0.27", "0.00", "10000"), ("0.27", "0.01", "10000"),
                                                   ("0.30", "0.00", "10000"), ("0.30", "0.01", "10000")], proc.stdout
    kappa = {(r[1], r[2]): float(r[4]) for r in rows}
    assert math.isnan(kappa[("0.27", "0.01")]) and math.isnan(kappa[("0.30", "0.01")])
    # κ(E) grows with E (paper Fig. 2b): 0.27 → ~0.14, 0.30 → ~0.19
    assert 0.10 < kappa[("0.27", "0.00")] < kappa[("0.30", "0.00")] < 0.3
    assert (tmp_path / "runs" / "mine.png").stat().st_size > 10_000
