"""Scene inputs: every number bounded, defaults derived from the system, −0 the same as 0, no silent empty window.

Each case a hostile input that used to run with exit 0 (wrong or endless numbers); each now a ConfigError naming
the key and the reason, or (−0, the IC radius) the right scene.
"""

import json

import pytest

from hhscatter.errors import ConfigError
from hhscatter.scene.grid import Grid
from hhscatter.scene.scene import Scene, SectionWindow, scene_from_dict

HH = "x**2/2 + y**2/2 + x**2*y - y**3/3"


@pytest.mark.parametrize(
    "changes,message",
    [
        (
            {"t_max": 1e300},
            r"t_max must be ≤ 1e\+07/ω = 1e\+07, got 1e\+300 \(every orbit still inside at t_max is "
            r"integrated all the way",
        ),
        ({"seed": 10**30}, r"seed must be ≤ 2\*\*63 − 1 = 9223372036854775807, got 10{30}"),
        ({"chunk_size": 10**12}, r"chunk_size must be ≤ 1e\+07, got 1e\+12 \(a chunk's rows are held in memory"),
        ({"seed": True}, r"seed must be an integer ≥ 0, got True"),
    ],
)
def test_every_number_is_bounded(changes, message):
    with pytest.raises(ConfigError, match=message):
        Scene(energy=0.3, n=10, **changes)


def test_minus_zero_is_zero():
    zero = Scene(energy=0.3, n=10, gamma=0.0)
    minus = Scene(energy=0.3, n=10, gamma=-0.0, sections=SectionWindow(t_from=-0.0))
    assert str(minus.gamma) == "0.0" and str(minus.sections.t_from) == "0.0"
    assert minus.replace(sections=None).result_hash() == zero.result_hash()
    grid = Grid(zero, energies=(0.3,), gammas=(-0.0, 0.01))
    assert [Grid.partition(p) for p in grid.points] == ["E0.3_gamma0.0", "E0.3_gamma0.01"]


def test_the_ic_radius_is_the_systems():
    # half the saddle distance r_s: 0.5 for Hénon–Heiles, 1.0 for Contopoulos (saddles at distance 2)
    assert Scene(energy=0.3, n=10).radius == 0.5
    conto = Scene(energy=1.2, n=10, system={"name": "contopoulos"})
    assert conto.model.saddle_radius == pytest.approx(2.0) and conto.radius == pytest.approx(1.0)
    assert Scene(energy=1.2, n=10, radius=0.5, system={"name": "contopoulos"}).radius == 0.5  # given: kept


def test_a_declared_systems_scene_carries_no_henon_heiles_keys_and_keeps_its_hash():
    s = Scene(energy=0.3, n=100, seed=3, system={"potential": HH})
    d = json.loads(s.to_json())
    assert "omega" not in d and "lam" not in d and d["system"]["potential"] == HH
    # the hash the same scene had when its scene.json still carried omega = lam = 1 (recorded with that code)
    assert s.result_hash() == "9b5f95ec71b57e3a1833e8e859e56b8a4590b5593b2699aa128d041fd0b58f0a"
    assert scene_from_dict(d).result_hash() == s.result_hash()
    conto = Scene(energy=1.2, n=100, seed=3, radius=1.0, system={"name": "contopoulos"})
    assert conto.result_hash() == "3a423ba10c88b1cec43d4bcd56ca158c495e428e9b06122ae83bd2d2f0a5d92a"


def test_a_section_window_above_e0_is_refused():
    with pytest.raises(
        ConfigError,
        match=r"sections.e_min = 0.5 is above E0 = 0.3: the energy never rises above E0, "
        "so no crossing would be recorded",
    ):
        Scene(energy=0.3, n=10, sections=SectionWindow(e_min=0.5))


def test_an_energy_within_rounding_of_ec_is_refused():
    ec = 1 / 6
    one_ulp = 0.16666666666666669
    assert one_ulp > ec
    with pytest.raises(
        ConfigError,
        match=r"energy must exceed E_c = 0.16666666666666666 by more than 1e-09 E_c, got "
        r"0.16666666666666669 \(E0 − E_c = 2.78e-17\)",
    ):
        Scene(energy=one_ulp, n=50, gamma=0.01)
    assert Scene(energy=ec * (1 + 1e-6), n=50, gamma=0.01).energy > ec


@pytest.mark.parametrize("ics", ["", "   "])
def test_an_empty_ic_path_is_refused(ics):
    with pytest.raises(ConfigError, match=f"ics must be the path of a Parquet/CSV table, got '{ics}'"):
        Scene(energy=None, n=1, ics=ics)


def test_a_region_without_radius_keeps_the_unused_field_and_its_hash():
    # the well and the square read no radius: their scenes keep the field's old value, hence their hashes
    well = Scene(energy=1.2, n=10, region="well", system={"name": "contopoulos"})
    assert well.radius == 0.5 and well.result_hash() == well.replace(radius=0.5).result_hash()
