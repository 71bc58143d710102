"""Tables, runner and CLI: schema, metadata, determinism, resume, bad input."""

import json
import math

import numpy as np
import pandas as pd
import pytest

from hhscatter import read_lifetimes, read_sections, read_snapshots
from hhscatter.cli import main
from hhscatter.data.read import read_meta
from hhscatter.errors import OutputError
from hhscatter.run.runner import simulate
from hhscatter.scene.scene import Scene, SceneError, SectionWindow


def _files(d):
    return {p.relative_to(d): p.read_bytes() for p in sorted(d.rglob("part-*.parquet"))}


@pytest.fixture(scope="module")
def small_diss():
    return Scene(
        energy=0.3,
        gamma=0.01,
        n=900,
        seed=5,
        chunk_size=300,
        sections=SectionWindow(t_from=10.0, first_only=True),
        snapshots=(0.0, 5.0, 10.0, 20.0),
    )


def test_one_and_two_workers_give_byte_identical_tables(tmp_path, small_diss):
    simulate(small_diss, tmp_path / "w1", workers=1, progress=False)
    simulate(small_diss, tmp_path / "w2", workers=2, progress=False)
    a, b = _files(tmp_path / "w1"), _files(tmp_path / "w2")
    assert len(a) == 9 and a.keys() == b.keys()
    assert all(a[k] == b[k] for k in a)


def test_tables_schema_metadata_and_readers(tmp_path, small_diss):
    import duckdb

    out = tmp_path / "run"
    summary = simulate(small_diss, out, workers=1, progress=False)
    lt = read_lifetimes(out)
    assert len(lt) == 900 and lt["traj_id"].is_unique and lt["traj_id"].dtype == np.int64
    assert set(lt["outcome"]) <= {"escaped", "settled", "censored"}
    assert summary.escaped + summary.settled + summary.censored == 900
    assert lt.loc[lt.outcome != "escaped", "exit_channel"].isna().all()
    assert lt.loc[lt.outcome == "escaped", "exit_channel"].isin([0, 1, 2]).all()
    sec, snap = read_sections(out), read_snapshots(out)
    assert (sec.groupby("traj_id").size() == 1).all() and (sec["t"] >= 10).all()
    assert set(snap["t"]) <= {0.0, 5.0, 10.0, 20.0}
    # plain pandas and DuckDB read the same dataset
    plain = pd.read_parquet(out / "lifetimes")
    assert len(plain) == 900
    n = duckdb.sql(f"select count(*) from read_parquet('{out}/lifetimes/*.parquet')").fetchall()[0][0]
    assert n == 900
    meta = read_meta(next((out / "lifetimes").glob("part-*.parquet")))
    assert meta["scene"]["gamma"] == 0.01 and meta["scene_hash"] == small_diss.result_hash()
    for key in ("hhscatter", "heyoka", "numpy", "pyarrow", "git_commit", "chunk", "orbits", "rows"):
        assert key in meta


def test_resume_skips_verified_chunks_and_redoes_damaged(tmp_path):
    sc = Scene(energy=0.27, n=600, seed=3, chunk_size=200)
    out = tmp_path / "r"
    simulate(sc, out, workers=1, progress=False)
    before = _files(out)
    victim = out / "lifetimes" / "part-000001.parquet"
    victim.write_bytes(victim.read_bytes()[:100])  # truncated file
    (out / "lifetimes" / "part-000002.parquet").unlink()
    s = simulate(sc, out, workers=1, resume=True, progress=False)
    assert s.chunks_skipped == 1 and s.chunks_done == 2
    assert _files(out) == before
    with pytest.raises(OutputError, match="different scene"):
        simulate(sc.replace(seed=4), out, workers=1, resume=True, progress=False)


def test_cli_simulate_and_survival(tmp_path, capsys):
    out = tmp_path / "cli"
    rc = main(
        ["simulate", "--energy", "0.27", "-n", "500", "--seed", "1", "--out", str(out), "--quiet", "--workers", "1"]
    )
    assert rc == 0
    line = capsys.readouterr().out
    assert "500 orbits: escaped" in line and "µs per orbit" in line
    rc = main(["survival", str(out), "--png", str(tmp_path / "p.png")])
    assert rc == 0 and (tmp_path / "p.png").stat().st_size > 1000


def test_cli_ics_table(tmp_path):
    from hhscatter.scene.ics import region_ics

    sc = Scene(energy=0.3, n=50, seed=8)
    ics = region_ics(sc, 0, 50)
    df = pd.DataFrame(ics, columns=["x", "y", "px", "py"])
    df["traj_id"] = np.arange(1000, 1050)
    df.to_csv(tmp_path / "ics.csv", index=False)
    assert (
        main(
            ["simulate", "--ics", str(tmp_path / "ics.csv"), "--out", str(tmp_path / "o"), "--quiet", "--workers", "1"]
        )
        == 0
    )
    lt = read_lifetimes(tmp_path / "o")
    assert list(lt["traj_id"]) == list(range(1000, 1050))
    assert np.allclose(lt["e0"], 0.3)


BAD = [
    (["--energy", "0.3", "--gamma", "-0.1", "-n", "10"], "gamma must be ≥ 0"),
    (["--energy", "0.3", "-n", "0"], "n (number of orbits) must be an integer > 0"),
    (["--energy", "nan", "-n", "10"], "energy must be finite"),
    (["--energy", "0.3", "-n", "10", "--gamma", "inf"], "gamma must be finite"),
    (["--energy", "0.3", "-n", "10", "--tol", "1e-3"], "tol must be in [1e-18, 1e-06]"),
    (["--energy", "0.3", "-n", "10", "--tol", "1e-20"], "tol must be in [1e-18, 1e-06]"),
    (["--energy", "-0.1", "-n", "10"], "energy must be > 0 = min V"),
    (["--energy", "0.15", "-n", "10"], "energy must be > E_c = 0.1666666667 in a conservative escape scene"),
    (["--energy", "0.3", "-n", "10", "--t-max", "0"], "t_max must be > 0"),
    (["--energy", "0.3", "-n", "10", "--r-esc", "0.9"], "r_esc must be > the saddle distance"),
]


@pytest.mark.parametrize("args,message", BAD, ids=[m.split()[0] + str(i) for i, (_, m) in enumerate(BAD)])
def test_bad_input_fails_before_work(tmp_path, capsys, args, message):
    out = tmp_path / "never"
    assert main(["simulate", *args, "--out", str(out), "--quiet"]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()  # nothing was written


def test_bad_output_and_ics(tmp_path, capsys):
    full = tmp_path / "full"
    full.mkdir()
    (full / "x.txt").write_text("keep me")
    assert main(["simulate", "--energy", "0.3", "-n", "5", "--out", str(full), "--quiet"]) == 2
    assert "not empty; pass --overwrite" in capsys.readouterr().err
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        import os

        if os.access(ro, os.W_OK):  # running as root: permissions do not bind, use a file as parent
            target = full / "x.txt" / "sub"
        else:
            target = ro / "sub"
        assert main(["simulate", "--energy", "0.3", "-n", "5", "--out", str(target), "--quiet"]) == 2
        assert "out:" in capsys.readouterr().err
    finally:
        ro.chmod(0o700)
    pd.DataFrame({"x": [0.1], "y": [0.2], "px": [0.3]}).to_csv(tmp_path / "a.csv", index=False)
    assert main(["simulate", "--ics", str(tmp_path / "a.csv"), "--out", str(tmp_path / "o1"), "--quiet"]) == 2
    assert "lacks column(s) ['py']" in capsys.readouterr().err
    pd.DataFrame({"x": [0.1], "y": [0.2], "px": [0.3], "py": [math.inf]}).to_csv(tmp_path / "b.csv", index=False)
    assert main(["simulate", "--ics", str(tmp_path / "b.csv"), "--out", str(tmp_path / "o2"), "--quiet"]) == 2
    assert "non-finite" in capsys.readouterr().err


def test_scene_toml_and_scales(tmp_path):
    from hhscatter.scene.schema import load_scene

    p = tmp_path / "scene.toml"
    p.write_text(
        "[scene]\nenergy = 0.3\nn = 100\ngamma = 0.01\n[sections]\nt_from = 17.0\nfirst_only = true\n"
        "[snapshots]\nstart = 0\nstop = 10\nstep = 5\n[scale.paper]\nn = 10000000\n"
    )
    sc = load_scene(p)
    assert sc.n == 100 and sc.sections.t_from == 17.0 and sc.snapshots == (0.0, 5.0, 10.0)
    assert load_scene(p, scale="paper").n == 10_000_000
    with pytest.raises(SceneError, match="scale must be one of"):
        load_scene(p, scale="huge")
    p.write_text("[scene]\nenergy = 0.3\nn = 100\nbogus = 1\n")
    with pytest.raises(SceneError, match=r"\[scene\] unknown key .bogus.; allowed keys: batch_size"):
        load_scene(p)
    assert json.loads(sc.to_json())["sections"]["t_to"] == "inf"
