"""Several runs read together stay apart (one point per run), the same run twice is refused, pooling is an
explicit and checked choice, and the physical parameters of an analysis come from the data, never a number
typed again that contradicts it."""

import math

import pandas as pd
import pytest

import hhscatter
from hhscatter.api import kappa_cmeasure_tables


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("runs")
    base = hhscatter.Scene(
        energy=0.3, n=300, seed=1, t_max=120.0, sections=hhscatter.SectionWindow(t_from=5.0, t_to=60.0)
    )
    for key, scene in (
        ("r15", base),
        ("r103", base.replace(r_esc=1.03)),
        ("seed2", base.replace(seed=2)),
        ("decay", hhscatter.Scene(energy=0.3, gamma=0.01, n=60, seed=3, t_max=60.0, snapshots=[0.0, 10.0, 20.0, 30.0])),
    ):
        hhscatter.simulate(scene, d / key, workers=1, progress=False)
    return d


def test_the_same_run_twice_is_refused_however_it_is_spelled(runs):
    with pytest.raises(ValueError, match="given twice"):
        hhscatter.read_lifetimes([runs / "r15", runs / "r15"])
    with pytest.raises(ValueError, match="given twice"):
        hhscatter.read_lifetimes([runs / "r15", f"{runs}/./r15/"])


def test_a_copy_of_a_run_is_the_same_scene_and_refused(runs, tmp_path):
    import shutil

    shutil.copytree(runs / "r15", tmp_path / "copy")
    with pytest.raises(ValueError, match=r"hold the same scene \(result hash"):
        hhscatter.read_lifetimes([runs / "r15", tmp_path / "copy"])


def test_a_frame_holding_an_orbit_twice_is_refused_by_the_analysis(runs):
    one = hhscatter.read_lifetimes(runs / "r15")
    with pytest.raises(ValueError, match="orbits twice"):
        hhscatter.escape_rates(pd.concat([one, one], ignore_index=True))


def test_two_runs_at_one_energy_are_two_points_each_as_read_alone(runs):
    """Two escape radii at the same E0 and seed: one κ per run, each exactly that of the run read alone."""
    both = hhscatter.read_lifetimes([runs / "r15", runs / "r103"])
    got = hhscatter.escape_rates(both, detect_tail=False).to_frame().set_index("run")
    assert len(got) == 2 and set(got["n"]) == {300}
    for key in ("r15", "r103"):
        alone = hhscatter.escape_rates(hhscatter.read_lifetimes(runs / key), detect_tail=False).to_frame().iloc[0]
        row = got.loc[str(runs / key)]
        assert (row.kappa, row.kappa_err, row.energy, row.gamma) == (alone.kappa, alone.kappa_err, 0.3, 0.0)


def test_pooling_is_explicit_and_checks_the_runs_are_one_scene(runs):
    with pytest.raises(ValueError, match=r"r_esc is 1.5 and 1.03"):
        hhscatter.read_lifetimes([runs / "r15", runs / "r103"], pool=True)
    pooled = hhscatter.read_lifetimes([runs / "r15", runs / "seed2"], pool=True)
    assert pooled.attrs["hhscatter"]["pooled"] == [str(runs / "r15"), str(runs / "seed2")]
    ((key, df),) = hhscatter.api.split_points(pooled)
    assert key == (0.3, 0.0) and len(df) == 600
    with pytest.raises(ValueError, match="needs a list"):
        hhscatter.read_lifetimes(runs / "r15", pool=True)


def test_energy_decay_reads_e0_and_gamma_from_the_run_and_refuses_a_contradiction(runs):
    snaps = hhscatter.read_snapshots(runs / "decay")
    mu = hhscatter.energy_decay(snaps, window=(0.0, 30.0)).to_frame().iloc[0]
    right = hhscatter.energy_decay(snaps, window=(0.0, 30.0), energy=0.3, gamma=0.01).to_frame().iloc[0]
    assert (mu.energy, mu.gamma, mu.mu) == (0.3, 0.01, right.mu) and 0.7 < mu.mu < 1.1
    with pytest.raises(ValueError, match=r"energy=0.35 contradicts the data: E0 of .*decay is 0.3"):
        hhscatter.energy_decay(snaps, energy=0.35, gamma=0.02)
    with pytest.raises(ValueError, match=r"gamma=0.02 contradicts the data: γ of .*decay is 0.01"):
        hhscatter.energy_decay(snaps, energy=0.3, gamma=0.02)
    bare = pd.DataFrame(snaps.to_dict("list"))  # no record of the run: E0 from the energies at t = 0
    assert not bare.attrs
    with pytest.raises(ValueError, match=r"energy at t = 0 is 0.3"):
        hhscatter.energy_decay(bare, energy=0.35, gamma=0.01)


def test_kappa_cmeasure_tables_reads_the_window_and_t_max_and_refuses_mixed_runs(runs):
    lt, sec = hhscatter.read_lifetimes(runs / "r15"), hhscatter.read_sections(runs / "r15")
    row = kappa_cmeasure_tables(lt, sec, t_from=10.0, t_to=30.0, n_boot=20).to_frame().iloc[0]
    assert row.t_record_end == 60.0 and math.isfinite(row.kappa_pt)
    with pytest.raises(ValueError, match=r"t_max=200.0 contradicts the data: t_max of .*r15 is 120.0"):
        kappa_cmeasure_tables(lt, sec, t_max=200.0)
    with pytest.raises(ValueError, match="window=.* contradicts the data"):
        kappa_cmeasure_tables(lt, sec, window=hhscatter.SectionWindow(t_from=5.0, t_to=90.0))
    with pytest.raises(ValueError, match="come from different runs"):
        kappa_cmeasure_tables(lt, hhscatter.read_sections(runs / "r103"))
