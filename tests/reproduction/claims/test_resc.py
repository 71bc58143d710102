"""The r_esc sensitivity of the claims (hhscatter.reproduction.claims.resc): a second radius for every system, κ0's
shift between the radii by the one rule, each system's r_esc rule by energy."""

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.model.builtins import barbanis, contopoulos, henon_heiles
from hhscatter.reproduction.claims.keys import resc_key
from hhscatter.reproduction.claims.resc import r_esc_rule, resc_kappa_rows, resc_values


def test_the_second_radius_is_a_factor_of_each_systems_saddle_distance():
    """1.03 r_s beside the default: the paper's 1.03 for Hénon–Heiles (r_s = 1), 2.06 for Contopoulos ε = 0.25
    (saddles at x² = y² = 1/(2ε) = 2: r_s = 2), 1.03·√3 for Barbanis ε = 0.5 (r_s = √3); a factor not beyond the
    saddle is no radius."""
    p = SimpleNamespace(resc_values=[1.03, 0.95], e0_ratio=1.8)
    assert resc_values(p, henon_heiles()) == [None, pytest.approx(1.03)]
    assert resc_values(p, contopoulos(eps=0.25)) == [None, pytest.approx(2.06)]
    assert resc_values(p, barbanis(eps=0.5)) == [None, pytest.approx(1.03 * math.sqrt(3))]


def _lt(kappa, n=20000, t_max=800.0, n_censored=0, seed=4):
    t = np.minimum(np.random.default_rng(seed).exponential(1 / kappa, n), t_max)
    t[:n_censored] = t_max
    out = np.where(np.arange(n) < n_censored, "censored", "escaped")
    return pd.DataFrame({"traj_id": np.arange(n), "t_end": t, "outcome": pd.Categorical(out)})


class _Runs:
    def __init__(self, params, tables):
        self.params, self.tables = params, tables

    def lifetimes(self, key):
        return self.tables[key]


def _params():
    return SimpleNamespace(
        resc_values=[1.03], e0_ratio=1.8, resc_ratios=[1.8], min_survivors=50.0, max_plateau_bias=0.1
    )


def test_kappa0_shift_between_two_radii_is_stated_with_its_error_and_the_one_rules_verdict():
    """κ0 = 0.05 at the default radius and 0.06 at 1.03 (exponential lifetimes, 2·10⁴ orbits each): the shift
    0.06/0.05 − 1 = 0.2 is found within 3σ and called a shift; equal rates give no resolved shift."""
    spec = {"name": "henon_heiles", "params": {}}
    systems = [("hh", spec, henon_heiles())]
    runs = _Runs(
        _params(), {resc_key("hh", None, "r1.800"): _lt(0.05), resc_key("hh", 1.03, "r1.800"): _lt(0.06, seed=5)}
    )
    rows = {r["convention"]: r for r in resc_kappa_rows(runs, systems)}
    row = rows["plateau"]
    assert (row["r_esc_default"], row["r_esc"], row["e_ratio"], row["n"]) == (1.5, pytest.approx(1.03), 1.8, 20000)
    assert abs(row["shift"]["value"] - 0.2) < 3 * row["shift"]["err"]
    assert 0 < row["shift"]["err"] < 0.1
    assert row["verdict"].startswith("shifts (z = +")
    same = _Runs(_params(), {resc_key("hh", None, "r1.800"): _lt(0.05), resc_key("hh", 1.03, "r1.800"): _lt(0.05)})
    (row,) = [r for r in resc_kappa_rows(same, systems) if r["convention"] == "plateau"]
    assert row["shift"]["value"] == 0.0 and row["verdict"].startswith("no shift resolved")


def test_kappa0_ill_defined_at_one_radius_leaves_the_shift_undetermined_with_the_reason():
    """400 of 2·10⁴ orbits still inside at t_max at 1.03: the plateau check fails there (all orbits), the escaping
    orbits' κ0 is defined at both radii."""
    spec = {"name": "henon_heiles", "params": {}}
    runs = _Runs(
        _params(),
        {resc_key("hh", None, "r1.800"): _lt(0.05), resc_key("hh", 1.03, "r1.800"): _lt(0.05, n_censored=400)},
    )
    rows = {r["convention"]: r for r in resc_kappa_rows(runs, [("hh", spec, henon_heiles())])}
    assert rows["plateau"]["shift"]["value"] is None
    assert rows["plateau"]["verdict"].startswith("undetermined: κ0 ill-defined at r_esc = 1.03: plateau")
    assert rows["escaping"]["shift"]["value"] is not None


def test_the_r_esc_rule_states_a_fixed_radius_and_one_that_grows_with_energy():
    """Hénon–Heiles keeps 1.5 (inside R(E) = √(6E) once E > 0.375 = 2.25 E_c); Contopoulos ε = 0.25 uses
    max(1.5 r_s, R(E)) = 3 near threshold and grows at high energy."""
    ratios = [1.05, 1.5, 2.2, 2.6, 5.0]
    hh = r_esc_rule(henon_heiles(), ratios)
    assert [x["r_esc"] for x in hh["by_ratio"]] == [1.5] * 5
    assert hh["rule"].startswith("1.5 at every E (inside the no-return radius R(E) from 2.6 E_c on")
    assert hh["by_ratio"][-1]["no_return_radius"] == pytest.approx(math.sqrt(6 * 5 / 6))
    co = r_esc_rule(contopoulos(eps=0.25), ratios)
    r = [x["r_esc"] for x in co["by_ratio"]]
    assert r[0] == pytest.approx(3.0) and r[-1] > r[-2] > r[0]
    assert co["by_ratio"][0]["from"] == "1.5 r_s" and co["by_ratio"][-1]["from"] == "R(E)"
    assert co["rule"].startswith("max(1.5 r_s, R(E)) = 3 up to")
