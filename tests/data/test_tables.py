"""Grid datasets open identically in hhscatter, pandas, pyarrow, DuckDB and polars; old-layout runs still read and resume."""

import json
import shutil

import numpy as np
import pandas as pd
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest

from hhscatter import read_lifetimes, read_sections, read_snapshots
from hhscatter.data.read import read_meta, survival_arrays
from hhscatter.data.write import write_part
from hhscatter.run.runner import simulate
from hhscatter.scene.grid import Grid
from hhscatter.scene.scene import Scene, SectionWindow

KEYS = ["energy", "gamma", "traj_id"]
COLS = ["traj_id", "energy", "gamma", "e0", "x0", "outcome", "t_end", "e_end"]


@pytest.fixture(scope="module")
def grid():
    base = Scene(
        energy=0.25,
        n=60,
        seed=23,
        chunk_size=30,
        name="five",
        sections=SectionWindow(t_from=1.0, first_only=True),
        snapshots=(0.0, 2.0, 4.0),
    )
    return Grid(base, (0.25, 0.3), (0.0, 0.01))


@pytest.fixture(scope="module")
def run(tmp_path_factory, grid):
    out = tmp_path_factory.mktemp("five") / "run"
    simulate(grid, out, workers=1, progress=False)
    return out


def _same_frame(df):
    """The compared frame: fixed columns, rows in (energy, gamma, traj_id) order, outcome as plain str."""
    for k in ("energy", "gamma", "e0", "t_end"):
        assert df[k].dtype == np.float64, (k, df[k].dtype)
    df = df[COLS].sort_values(KEYS).reset_index(drop=True)
    return df.assign(outcome=df["outcome"].astype(str).astype(object))


def test_five_readers_give_the_same_frame(run):
    import duckdb
    import polars as pl

    ours = _same_frame(read_lifetimes(run))
    assert len(ours) == 240 and ours.groupby(["energy", "gamma"]).size().tolist() == [60] * 4
    frames = {
        "pandas": pd.read_parquet(run / "lifetimes"),
        "pyarrow": ds.dataset(run / "lifetimes", format="parquet", partitioning="hive").to_table().to_pandas(),
        "duckdb": duckdb.sql(
            f"select * from read_parquet('{run}/lifetimes/**/*.parquet', hive_partitioning=true)"
        ).df(),
        "polars": pl.scan_parquet(run / "lifetimes", hive_partitioning=True).collect().to_pandas(),
    }
    for name, df in frames.items():
        assert set(df.columns) == set(read_lifetimes(run).columns), name  # no extra key columns
        pd.testing.assert_frame_equal(_same_frame(df), ours, obj=name)
    # a numeric filter on the point columns works in SQL (the old layout gave VARCHAR keys)
    n = duckdb.sql(
        f"select count(*) from read_parquet('{run}/lifetimes/**/*.parquet', hive_partitioning=true) "
        "where gamma > 0.001 and energy = 0.3"
    ).fetchall()[0][0]
    assert n == 60


def test_sections_and_snapshots_keep_their_energy_and_name_their_point(run):
    import duckdb

    for read, name in ((read_sections, "sections"), (read_snapshots, "snapshots")):
        ours = read(run).sort_values(["point_energy", "point_gamma", "traj_id", "t"]).reset_index(drop=True)
        raw = pd.read_parquet(run / name).sort_values(["point_energy", "point_gamma", "traj_id", "t"])
        pd.testing.assert_frame_equal(raw.reset_index(drop=True), ours, obj=name)
        sql = duckdb.sql(f"select * from read_parquet('{run}/{name}/**/*.parquet', hive_partitioning=true)").df()
        assert len(sql) == len(ours) and set(sql.columns) == set(ours.columns)
        # `energy` is the orbit's energy at t: with drag it is below the point's E0 after t = 0
        late = ours[(ours["point_gamma"] > 0) & (ours["t"] > 0.5)]
        assert len(late) and (late["energy"] < late["point_energy"]).all()


# -- runs written in the layout of hhscatter <= 0.1.0 ----------------------------------
def _to_old_layout(run, dest):
    """Rewrite a grid run as hhscatter 0.1.0 wrote it: hive folders energy=…/gamma=…, no point columns."""
    shutil.copytree(run, dest)
    extra = {
        "lifetimes": ["energy"],
        "sections": ["point_energy", "point_gamma"],
        "snapshots": ["point_energy", "point_gamma"],
    }
    for f in sorted(dest.rglob("part-*.parquet")):
        name = f.relative_to(dest).parts[0]
        meta = read_meta(f)
        e, g = meta["scene"]["energy"], meta["scene"]["gamma"]
        table = pq.read_table(f).drop_columns(extra[name])
        write_part(dest / name / f"energy={e!r}" / f"gamma={g!r}" / f.name, table, meta)
        f.unlink()
        if not any(f.parent.iterdir()):
            f.parent.rmdir()
    doc = json.loads((dest / "scene.json").read_text())
    for p in doc["points"]:
        e, g = p["partition"].removeprefix("E").split("_gamma")
        p["partition"] = f"energy={e}/gamma={g}"
    doc.pop("manifest")  # hhscatter 0.1.0 wrote no manifest (its runs are read by listing their parts)
    (dest / "scene.json").write_text(json.dumps(doc))
    return dest


@pytest.fixture(scope="module")
def old_run(run, tmp_path_factory):
    return _to_old_layout(run, tmp_path_factory.mktemp("old") / "run")


def test_old_layout_fixture_is_the_old_convention(old_run):
    parts = sorted(p.relative_to(old_run).as_posix() for p in old_run.rglob("part-*.parquet"))
    assert "lifetimes/energy=0.3/gamma=0.01/part-000001.parquet" in parts and len(parts) == 24
    assert "energy" not in pq.read_schema(old_run / "lifetimes/energy=0.3/gamma=0.01/part-000001.parquet").names
    with pytest.raises(Exception, match="gamma"):  # what the issue measured: pandas cannot open it
        pd.read_parquet(old_run / "lifetimes")


def test_old_layout_reads_like_the_new_one(run, old_run):
    pd.testing.assert_frame_equal(_same_frame(read_lifetimes(old_run)), _same_frame(read_lifetimes(run)))
    for read in (read_sections, read_snapshots):
        order = ["point_energy", "point_gamma", "traj_id", "t"]
        a = read(old_run).sort_values(order).reset_index(drop=True)
        b = read(run).sort_values(order).reset_index(drop=True)
        pd.testing.assert_frame_equal(a[b.columns], b)
    point = (ds.field("energy") == 0.3) & (ds.field("gamma") == 0.01)
    old, new = survival_arrays(old_run, filters=point), survival_arrays(run, filters=point)
    assert len(old[0]) == 60 and np.array_equal(np.sort(old[0]), np.sort(new[0])) and old[1].sum() == new[1].sum()


def test_old_layout_run_resumes_in_its_own_layout(grid, old_run, tmp_path):
    out = tmp_path / "old"
    shutil.copytree(old_run, out)

    def tables():
        return {p.relative_to(out).as_posix(): (pq.read_table(p), read_meta(p)) for p in out.rglob("part-*.parquet")}

    before = tables()
    (out / "lifetimes/energy=0.25/gamma=0.01/part-000001.parquet").unlink()
    (out / "sections/energy=0.25/gamma=0.01/part-000001.parquet").unlink()
    s = simulate(grid, out, workers=1, resume=True, progress=False)
    assert s.chunks_done == 1 and s.chunks_skipped == 7
    after = tables()
    assert after.keys() == before.keys()  # redone in the old folders ...
    for k, (table, meta) in after.items():  # ... without point columns, same rows and metadata
        assert table.equals(before[k][0]) and meta == before[k][1], k
    assert [p["partition"] for p in json.loads((out / "scene.json").read_text())["points"]][
        1
    ] == "energy=0.25/gamma=0.01"


def test_read_lifetimes_categorical_is_the_same_table_at_one_byte_per_outcome(run):
    """categorical=True (the route for 1e7 orbits): the same labels, as a pandas categorical."""
    import pandas as pd

    from hhscatter.data.read import read_lifetimes

    plain = read_lifetimes(run)
    cat = read_lifetimes(run, categorical=True)
    assert isinstance(cat["outcome"].dtype, pd.CategoricalDtype)
    assert not isinstance(plain["outcome"].dtype, pd.CategoricalDtype)
    assert list(cat["outcome"].astype(str)) == list(plain["outcome"])
    assert cat["outcome"].cat.codes.dtype.itemsize == 1
    pd.testing.assert_frame_equal(cat.drop(columns="outcome"), plain.drop(columns="outcome"))


def test_read_by_orbit_is_the_lifetimes_table_in_orbit_order(run):
    """read_by_orbit: numpy columns in traj_id order, outcome as a 1-byte categorical, null channels as −1."""
    import pandas as pd

    from hhscatter.data.read import read_by_orbit, read_lifetimes

    ref = read_lifetimes(run).sort_values("traj_id", kind="stable").reset_index(drop=True)
    c = read_by_orbit(run, ["t_end", "outcome", "exit_channel"])
    assert set(c) == {"traj_id", "t_end", "outcome", "exit_channel"}
    np.testing.assert_array_equal(c["traj_id"], ref["traj_id"].to_numpy())
    np.testing.assert_array_equal(c["t_end"], ref["t_end"].to_numpy())
    assert isinstance(c["outcome"], pd.Categorical) and list(c["outcome"].astype(str)) == list(ref["outcome"])
    want = ref["exit_channel"].astype("Float64").to_numpy(dtype=float, na_value=-1.0)
    np.testing.assert_array_equal(c["exit_channel"].astype(float), want)
