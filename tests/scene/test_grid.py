"""Grid runs: lists of energies/γ → one job, one folder per point (no hive keys), paired ICs, resume."""

import numpy as np
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest

from hhscatter.cli import main
from hhscatter.data.read import read_lifetimes, read_meta, read_sections
from hhscatter.errors import OutputError
from hhscatter.model import HenonHeiles
from hhscatter.run.runner import simulate
from hhscatter.scene.grid import Grid, load_run
from hhscatter.scene.scene import Scene, SceneError
from hhscatter.scene.schema import load_scene

ENERGIES, GAMMAS = (0.25, 0.3), (0.0, 0.01)


@pytest.fixture(scope="module")
def grid():
    from hhscatter.scene.scene import SectionWindow

    base = Scene(
        energy=0.25, n=160, seed=17, chunk_size=80, sections=SectionWindow(t_from=2.0, first_only=True), name="sweep"
    )
    return Grid(base, ENERGIES, GAMMAS)


@pytest.fixture(scope="module")
def grid_run(tmp_path_factory, grid):
    out = tmp_path_factory.mktemp("grid") / "g"
    s = simulate(grid, out, workers=2, progress=False)
    assert s.n == 4 * 160 and s.chunks_done == 8
    return out


def test_toml_lists_make_a_grid_and_scalars_a_scene(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text("[scene]\nenergy = [0.25, 0.3]\ngamma = [0, 0.01]\nn = 100\n")
    g = load_run(p)
    assert isinstance(g, Grid) and g.n == 400
    assert [(s.energy, s.gamma) for s in g.points] == [(0.25, 0.0), (0.25, 0.01), (0.3, 0.0), (0.3, 0.01)]
    assert [Grid.partition(s) for s in g.points][1] == "E0.25_gamma0.01"
    with pytest.raises(SceneError, match="that is a grid run"):
        load_scene(p)
    p.write_text("[scene]\nenergy = 0.3\nn = 100\n")
    assert isinstance(load_run(p), Scene)


@pytest.mark.parametrize(
    "energies,gammas,message",
    [
        ([0.3, 0.3], [0.0], "energy lists a value twice"),
        ([0.3, 0.1], [0.0], "energy must be > E_c"),
        ([0.3], [0.0, -0.01], "gamma must be ≥ 0"),
        ([0.3, float("nan")], [0.0], "energy must be finite"),
        ([], [0.0], "non-empty list"),
    ],
)
def test_bad_grids_name_the_parameter(energies, gammas, message):
    with pytest.raises(SceneError, match=message):
        Grid(Scene(energy=0.3, n=10), energies, gammas)


def test_layout_metadata_and_partition_columns(grid, grid_run):
    parts = sorted(p.relative_to(grid_run).as_posix() for p in grid_run.rglob("part-*.parquet"))
    assert len(parts) == 16
    assert "lifetimes/E0.3_gamma0.01/part-000001.parquet" in parts
    assert "sections/E0.25_gamma0.0/part-000000.parquet" in parts
    assert not any("=" in p for p in parts)  # no hive keys to clash with the files' columns
    for scene in grid.points:
        meta = read_meta(grid_run / "lifetimes" / Grid.partition(scene) / "part-000000.parquet")
        assert (meta["scene"]["energy"], meta["scene"]["gamma"]) == (scene.energy, scene.gamma)
        assert meta["scene_hash"] == scene.result_hash()
    lt = read_lifetimes(grid_run)
    assert len(lt) == 640
    assert lt.groupby(["energy", "gamma"]).size().to_dict() == {(e, g): 160 for e in ENERGIES for g in GAMMAS}
    assert (lt["gamma"] == lt["gamma"].astype(float)).all()
    # the per-orbit e0 is the orbit's own computed energy, not shadowed by the partition value
    assert np.allclose(lt["e0"], lt["energy"], rtol=0, atol=1e-14)
    assert (lt["e0"] != lt["energy"]).any()
    # plain pyarrow reads the same dataset, the point columns from the files
    t = ds.dataset(grid_run / "lifetimes", format="parquet", partitioning="hive").to_table(
        filter=(ds.field("energy") == 0.3) & (ds.field("gamma") == 0.01), columns=["traj_id", "t_end"]
    )
    assert t.num_rows == 160
    one = read_lifetimes(
        grid_run, columns=["traj_id", "t_end"], filters=(ds.field("energy") == 0.3) & (ds.field("gamma") == 0.01)
    )
    assert one.sort_values("traj_id")["t_end"].tolist() == t.sort_by("traj_id").column("t_end").to_pylist()
    sec = read_sections(grid_run)
    assert {"point_energy", "point_gamma"} <= set(sec.columns) and (sec["t"] >= 2.0).all()
    assert sec.groupby(["point_energy", "point_gamma"]).ngroups == 4
    # the crossing energy is the orbit's own (below E0 with drag), not the point's nominal E0
    diss = sec[sec["point_gamma"] > 0]
    assert (diss["energy"] < diss["point_energy"] - 1e-6).all()


def test_each_point_equals_a_plain_run_of_that_scene(tmp_path, grid, grid_run):
    scene = grid.points[3]  # E0 = 0.3, γ = 0.01
    simulate(scene, tmp_path / "plain", workers=1, progress=False)
    for name, extra in (("lifetimes", ["energy"]), ("sections", ["point_energy", "point_gamma"])):
        a = pq.read_table(tmp_path / "plain" / name / "part-000001.parquet")
        b = pq.read_table(grid_run / name / Grid.partition(scene) / "part-000001.parquet")
        assert b.column_names == a.column_names + extra
        assert b.drop_columns(extra).equals(a) and a.schema.metadata == b.schema.metadata
        for col, key in zip(extra, ("energy", "gamma")):
            assert set(b.column(col).to_pylist()) == {getattr(scene, key)}


def test_paired_initial_conditions(grid_run):
    """Same seed at every point: same positions; speeds from each point's energy (closed form)."""
    lt = read_lifetimes(grid_run).sort_values(["energy", "gamma", "traj_id"])
    pos = {k: g[["x0", "y0"]].to_numpy() for k, g in lt.groupby(["energy", "gamma"])}
    ref = pos[(0.25, 0.0)]
    assert all(np.array_equal(v, ref) for v in pos.values())
    m = HenonHeiles(1.0, 1.0)
    for (e, _), g in lt.groupby(["energy", "gamma"]):
        speed2 = g["px0"] ** 2 + g["py0"] ** 2
        assert np.allclose(speed2, 2 * (e - m.potential(g["x0"], g["y0"])), rtol=1e-13, atol=1e-15)
        # tangential: x px + y py = 0 (on the section ṙ = 0)
        assert np.allclose(g["x0"] * g["px0"] + g["y0"] * g["py0"], 0, atol=1e-15)
    by_gamma = {k: g[["px0", "py0"]].to_numpy() for k, g in lt.groupby(["energy", "gamma"])}
    assert np.array_equal(by_gamma[(0.3, 0.0)], by_gamma[(0.3, 0.01)])


def test_grid_resume_and_refusal(tmp_path, grid, grid_run):
    import shutil

    out = tmp_path / "g"
    shutil.copytree(grid_run, out)
    before = {p: p.read_bytes() for p in out.rglob("part-*.parquet")}
    victim = out / "lifetimes" / "E0.25_gamma0.01" / "part-000001.parquet"
    victim.unlink()
    s = simulate(grid, out, workers=1, resume=True, progress=False)
    assert s.chunks_done == 1 and s.chunks_skipped == 7
    assert {p: p.read_bytes() for p in out.rglob("part-*.parquet")} == before
    with pytest.raises(OutputError, match="different scene"):
        simulate(Grid(grid.base, ENERGIES, (0.0, 0.02)), out, workers=1, resume=True, progress=False)


def test_cli_grid_lists(tmp_path, capsys):
    out = tmp_path / "c"
    rc = main(
        ["simulate", "--energy", "0.27,0.3", "-n", "50", "--seed", "2", "--out", str(out), "--workers", "1", "--quiet"]
    )
    assert rc == 0 and "100 orbits" in capsys.readouterr().out
    lt = read_lifetimes(out)
    assert sorted(set(lt["energy"])) == [0.27, 0.3] and set(lt["gamma"]) == {0.0}
    assert pq.read_metadata(next(out.rglob("part-*.parquet"))).num_rows == 50
    assert main(["simulate", "--energy", "0.27,inf", "-n", "5", "--out", str(tmp_path / "x"), "--quiet"]) == 2
    assert "energy must be finite" in capsys.readouterr().err


def test_streamed_survival_of_one_grid_point(grid_run):
    """survival_on_grid with a partition filter = Kaplan–Meier of that point's rows."""
    from hhscatter.analysis.survival.fits import survival_curve
    from hhscatter.api import stream_survival

    point = (ds.field("energy") == 0.3) & (ds.field("gamma") == 0.01)
    g = np.linspace(0.0, 30.0, 31)
    got = stream_survival(grid_run, g, filters=point)
    lt = read_lifetimes(grid_run, columns=["t_end", "outcome"], filters=point)
    assert len(lt) == 160
    ref = survival_curve(lt["t_end"].to_numpy(), (lt["outcome"] != "censored").to_numpy(), t_grid=g)
    assert np.allclose(got.P, ref.P, rtol=0, atol=1e-14) and got.P[0] == 1.0 and got.P[-1] < got.P[1]
