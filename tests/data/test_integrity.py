"""Fault injection: 12 cases, each at small N, each with its exact outcome.

Nothing wrong is read or published silently: every case ends in a clear refusal (its message asserted)
or in a correct result (byte-identical to an undisturbed run). Processes are started by the tests and
killed by their own PIDs only.
"""

import errno
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from hhscatter.cli import main
from hhscatter.data.read import read_lifetimes, read_sections, read_snapshots
from hhscatter.errors import IncompleteRunError, OutputError, RunIntegrityError, StudyError
from hhscatter.run.runner import simulate
from hhscatter.scene.scene import Scene, SectionWindow, scene_from_dict

SCENE = {
    "energy": 0.3,
    "gamma": 0.01,
    "n": 400,
    "seed": 11,
    "chunk_size": 100,
    "sections": SectionWindow(),
    "snapshots": (0.0, 5.0, 50.0),
}


def _hh(*args):
    return [sys.executable, "-c", "import sys; from hhscatter.cli import main; sys.exit(main())", *args]


def _parts(d):
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in sorted(Path(d).rglob("part-*.parquet"))}


@pytest.fixture(scope="module")
def base_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("integrity") / "base"
    simulate(Scene(**SCENE), out, workers=1, progress=False)
    return out


@pytest.fixture
def run(base_run, tmp_path):
    out = tmp_path / "run"
    shutil.copytree(base_run, out)
    return out


def _cli(capsys, *args):
    rc = main(list(args))
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return rc, err


# 1 -- a missing table folder, or a missing part, is refused (never read as another table)
def test_1_missing_table_or_part_is_refused(run):
    shutil.rmtree(run / "sections")
    with pytest.raises(RunIntegrityError, match=r"the sections table of the run at .* is missing"):
        read_sections(run)
    assert len(read_lifetimes(run)) == 400  # the other tables are intact and read
    (run / "snapshots" / "part-000002.parquet").unlink()
    with pytest.raises(RunIntegrityError, match=r"part-000002.parquet is missing, but its chunk is finished"):
        read_snapshots(run)


# 2 -- page checksums are verified on read
def test_2_damaged_data_page_is_refused_and_named(run):
    p = run / "sections" / "part-000001.parquet"
    cc = pq.ParquetFile(p).metadata.row_group(0).column(1)  # the t column
    b = bytearray(p.read_bytes())
    for k in range(3):
        b[cc.data_page_offset + cc.total_compressed_size // 2 + k] ^= 0xFF
    p.write_bytes(b)
    with pytest.raises(
        RunIntegrityError,
        match=r"sections/part-000001.parquet is damaged: a data page fails its "
        r"checksum",
    ):
        read_sections(run)


# 3 -- parts outside the chunk plan: refused by readers and by --resume
@pytest.mark.parametrize("what", ["duplicate", "junk", "foreign"])
def test_3_parts_outside_the_plan_are_refused(run, tmp_path, capsys, what):
    lt = run / "lifetimes"
    if what == "duplicate":
        shutil.copy(lt / "part-000000.parquet", lt / "part-000099.parquet")
    elif what == "junk":
        (lt / "part-junk.parquet").write_bytes(b"junk")
    else:  # another scene's part under a planned name
        other = tmp_path / "other"
        simulate(Scene(**{**SCENE, "seed": 12}), other, workers=1, progress=False)
        shutil.copy(other / "lifetimes" / "part-000001.parquet", lt / "part-000001.parquet")
    if what == "foreign":
        with pytest.raises(RunIntegrityError, match=r"part-000001.parquet was made by another scene"):
            read_lifetimes(run)
        with pytest.raises(
            RunIntegrityError, match=r"cannot resume: .*part-000001.parquet was made by a different scene"
        ):
            simulate(Scene(**SCENE), run, workers=1, progress=False, resume=True)
        return
    extra = "part-000099.parquet" if what == "duplicate" else "part-junk.parquet"
    with pytest.raises(
        RunIntegrityError,
        match=rf"1 file\(s\) in .*lifetimes are not in the run's chunk plan "
        rf"\(first: {extra}\)",
    ):
        read_lifetimes(run)
    rc, err = _cli(capsys, "simulate", "--out", str(run), "--resume", "--workers", "1", "--quiet")
    assert rc == 2 and f"1 part file(s) are not in this run's chunk plan (first: {run}/lifetimes/{extra})" in err


# 4 -- one writer per directory; --overwrite removes the old run completely
def test_4_second_writer_is_refused_while_the_first_runs(tmp_path, capsys):
    out = tmp_path / "run"
    proc = subprocess.Popen(
        _hh(
            "simulate",
            "--energy",
            "0.27",
            "-n",
            "20000",
            "--chunk-size",
            "200",
            "--workers",
            "1",
            "--quiet",
            "--out",
            str(out),
        ),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 120
        while not (out / "scene.json").exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        rc, err = _cli(
            capsys,
            "simulate",
            "--energy",
            "0.27",
            "-n",
            "100",
            "--out",
            str(out),
            "--overwrite",
            "--quiet",
            "--workers",
            "1",
        )
        assert rc == 2 and f"is being written by another process (pid {proc.pid})" in err
        assert "one writer per run directory" in err
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    # the killed writer left its lock file: the kernel released the lock, B runs and replaces A completely
    b = Scene(energy=0.3, n=300, seed=5, chunk_size=100)
    simulate(b, out, workers=1, progress=False, overwrite=True)
    ref = tmp_path / "ref"
    simulate(b, ref, workers=1, progress=False)
    assert _parts(out) == _parts(ref)
    assert len(read_lifetimes(out)) == 300
    assert "nothing to do" in simulate(b, out, workers=1, progress=False, resume=True).line()


def test_4_the_refused_writer_never_removes_the_holders_directory(tmp_path):
    from hhscatter.data.store import Store

    out = tmp_path / "fresh"
    fd = Store(out).lock()  # another writer has just made the directory and holds it (empty so far)
    try:
        with pytest.raises(OutputError, match=rf"being written by another process \(pid {os.getpid()}\)"):
            simulate(Scene(energy=0.3, n=10), out, workers=1, progress=False)
        assert out.is_dir() and (out / ".hhscatter.lock").exists()
    finally:
        Store.unlock(fd)


# 5 -- workers die with their parent (kill -9 and SIGTERM alike)
def _children(pid):
    import psutil

    return psutil.Process(pid).children(recursive=True)


def _running(p):
    import psutil

    try:
        return p.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_5_pool_workers_die_with_their_parent(tmp_path, sig):
    import psutil

    out = tmp_path / "run"
    proc = subprocess.Popen(
        _hh(
            "simulate",
            "--energy",
            "0.27",
            "-n",
            "40000",
            "--chunk-size",
            "500",
            "--workers",
            "2",
            "--quiet",
            "--out",
            str(out),
        ),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    kids = []
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not (out / "lifetimes" / "part-000000.parquet").exists():
            time.sleep(0.01)
        kids = _children(proc.pid)
        assert len(kids) >= 2, "the pool's workers were not found"
    finally:
        os.kill(proc.pid, sig)
        proc.wait()
    _, alive = psutil.wait_procs(kids, timeout=10)
    alive = [p for p in alive if _running(p)]  # a dead orphan may wait a moment as a zombie for init to reap it
    for p in alive:  # clean up before failing: only processes this test started
        p.kill()
    assert not alive, f"{len(alive)} worker(s) outlived their parent"
    n = len(list((out / "lifetimes").glob("part-*.parquet")))
    time.sleep(1.0)
    assert len(list((out / "lifetimes").glob("part-*.parquet"))) == n  # nobody writes any more


# 6 -- study stages check what they read
def test_6_analyze_refuses_stale_or_incomplete_raw_runs(tmp_path, base_run):
    from types import SimpleNamespace

    from hhscatter.studies import checked_raw_runs

    config = {"scene": {"energy": 0.3}, "study": {"x": 1, "paper_mu": 0.91}}
    study = SimpleNamespace(name="toy", scale="tiny", config=config, out=tmp_path / "out")
    study.param = lambda k: study.config["study"][k]
    raw = study.out / "raw"
    raw.mkdir(parents=True)
    shutil.copytree(base_run, raw / "E0.30")
    h = Scene(**SCENE).result_hash()
    done = {
        "study": "toy",
        "scale": "tiny",
        "inputs": {
            "tables": {"scene": {"energy": 0.3}, "sections": None, "snapshots": None, "follow": None},
            "study": {"x": 1},
        },  # simulate read [study] x only
        "runs": {"E0.30": {"scene_hash": h, "orbits": 400, "complete": True}},
    }
    (raw / "done.json").write_text(json.dumps(done))
    assert checked_raw_runs(study) == {"E0.30": {"scene_hash": h, "orbits": 400, "complete": True}}
    study.config = {**config, "study": {"x": 1, "paper_mu": 0.8}}  # an analysis-only key: no new simulation
    assert list(checked_raw_runs(study)) == ["E0.30"]
    study.config = {**config, "study": {"x": 2, "paper_mu": 0.91}}  # study.toml changed since simulate
    with pytest.raises(StudyError, match=r"were made from another study.toml \(\[study\] x \(1 → 2\) changed"):
        checked_raw_runs(study)
    study.config = {**config, "scene": {"energy": 0.35}}
    with pytest.raises(StudyError, match=r"another study.toml \(\[scene\] changed since simulate\)"):
        checked_raw_runs(study)
    study.config = config
    (raw / "E0.30" / "lifetimes" / "part-000003.parquet").unlink()  # a re-simulate killed halfway
    with pytest.raises(StudyError, match=r"raw run .*E0.30 is incomplete \(3 of 4 chunks finished\)"):
        checked_raw_runs(study)
    (raw / "done.json").unlink()  # simulate removes it before it starts
    with pytest.raises(StudyError, match=r"the simulate stage has not finished \(.*done.json is missing\)"):
        checked_raw_runs(study)


def test_6_simulate_stage_invalidates_its_done_record_first(tmp_path, monkeypatch):
    from types import SimpleNamespace

    from hhscatter.studies import _run_one

    study = SimpleNamespace(out=tmp_path, raw_runs={}, params_read=None)
    (tmp_path / "raw").mkdir()
    (tmp_path / "raw" / "done.json").write_text("{}")

    def killed(study, workers, progress):
        assert not (tmp_path / "raw" / "done.json").exists()
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _run_one(study, SimpleNamespace(simulate=killed), "simulate", "toy", "tiny", 1, False)
    assert not (tmp_path / "raw" / "done.json").exists()


# 7 -- partial runs: an error by default, a warning and consistent tables on request
def test_7_partial_run_is_an_error_unless_asked_for(run):
    (run / "lifetimes" / "part-000002.parquet").unlink()  # chunk 2 unfinished (lifetimes is written last)
    with pytest.raises(
        IncompleteRunError,
        match=r"incomplete: 1 of 4 chunk\(s\) \(100 of 400 orbits\) are not "
        r"finished; finish it with `hhscatter simulate --out .* --resume`",
    ):
        read_lifetimes(run)
    with pytest.raises(IncompleteRunError):
        read_sections(run)
    with pytest.warns(UserWarning, match=r"reading the 300 orbits of the finished chunks"):
        lt = read_lifetimes(run, allow_partial=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sec = read_sections(run, allow_partial=True)
    assert len(lt) == 300 and not set(range(200, 300)) & set(lt.traj_id)
    assert set(sec.traj_id) <= set(lt.traj_id)  # no section row of an orbit without a lifetimes row


# 8 -- an IC table below E_c with drag is refused (documented: such an orbit has no outcome)
def test_8_ics_below_ec_with_drag_are_refused(tmp_path, capsys):
    ics = tmp_path / "b.csv"
    ics.write_text("x,y,px,py\n0.05,0.02,0.05,0.05\n")
    rc, err = _cli(
        capsys,
        "simulate",
        "--ics",
        str(ics),
        "--gamma",
        "0.01",
        "--t-max",
        "200",
        "--out",
        str(tmp_path / "d8"),
        "--quiet",
    )
    assert rc == 2 and "1 row(s) start below E_c = 0.1666666667 inside r_esc with drag γ = 0.01 (first: row 0" in err
    assert not (tmp_path / "d8").exists()


# 9 -- bounds with reasons, before any work, nothing written
@pytest.mark.parametrize(
    "flags,message",
    [
        (["--r-esc", "1e50"], "r_esc must be ≤ 100 r_s = 100, got 1e+50 (energy conservation"),
        (["--radius", "1e300"], "radius must be ≤ r_esc = 1.5, got 1e+300"),
        (["--energy", "1e300"], "energy must be ≤ 1000 E_c = 166.667, got 1e+300"),
        (
            ["--gamma", "1e300"],
            "gamma must be ≤ 10 ω = 10 (ω the system's frequency), got 1e+300 (with the linear drag the motion is overdamped",
        ),
        (["--snapshots", "0:5000:1e-6"], "snapshots: 0:5000:1e-06 gives 5000000001 times, more than 100000"),
        (["-n", "1e12"], "n must be ≤ 1e+09 per run, got 1e+12"),
        (["-n", "1e8", "--chunk-size", "10"], "gives 10000000 chunks for n = 100000000, more than 100000 part files"),
        (["--t-max", "1e300"], "t_max must be ≤ 1e+07/ω = 1e+07, got 1e+300 (every orbit still inside at t_max"),
        (["--seed", "1e30"], "seed must be ≤ 2**63 − 1 = 9223372036854775807, got 1000000000000000019884624838656"),
        (["--chunk-size", "1e12"], "chunk_size must be ≤ 1e+07, got 1e+12 (a chunk's rows are held in memory"),
        (["--workers", "1e6"], "workers must be ≤ 1024, got 1000000 (one process each"),
    ],
)
def test_9_out_of_bounds_is_refused_before_any_work(tmp_path, capsys, flags, message):
    args = {"--energy": "0.3", "-n": "100", "--t-max": "5000", **dict(zip(flags[::2], flags[1::2]))}
    rc, err = _cli(capsys, "simulate", *[x for kv in args.items() for x in kv], "--out", str(tmp_path / "o"), "--quiet")
    assert rc == 2 and message in err, err
    assert not (tmp_path / "o").exists()


def test_9_huge_momenta_in_an_ic_table_are_refused(tmp_path, capsys):
    ics = tmp_path / "p.csv"
    ics.write_text("x,y,px,py\n0.1,0.0,0.0,0.8\n0.1,0.0,1e10,0.0\n")
    rc, err = _cli(capsys, "simulate", "--ics", str(ics), "--out", str(tmp_path / "o"), "--quiet")
    assert rc == 2 and "1 row(s) have an energy above 1000 E_c = 166.667 (first: row 1, E = 5e+19" in err
    assert not (tmp_path / "o").exists()


# 10 -- ENOSPC on scene.json, a bad scheduler, a broken pipe, a Dask cluster without workers
def test_10_enospc_on_scene_json_is_clear_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    from hhscatter.data.store import Store

    def full(self, rel, doc):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(Store, "write_json", full)
    rc, err = _cli(capsys, "simulate", "--energy", "0.3", "-n", "10", "--out", str(tmp_path / "o"), "--quiet")
    assert rc == 2 and "cannot write" in err and "scene.json (No space left on device); nothing was computed" in err
    assert not (tmp_path / "o").exists()


def test_10_bad_scheduler_is_refused(tmp_path, capsys):
    pytest.importorskip("distributed")
    rc, err = _cli(
        capsys,
        "simulate",
        "--energy",
        "0.3",
        "-n",
        "10",
        "--out",
        str(tmp_path / "o"),
        "--quiet",
        "--scheduler",
        "foo://bar",
    )
    assert rc == 2 and "scheduler must be 'local' or an address like tcp://host:8786" in err
    assert not (tmp_path / "o").exists()


def test_10_broken_pipe_is_quiet(tmp_path):
    import shlex

    cmd = (
        shlex.join(
            _hh("simulate", "--energy", "0.3", "-n", "20", "--workers", "1", "--quiet", "--out", str(tmp_path / "o"))
        )
        + " | head -c 1"
    )
    r = subprocess.run(cmd, shell=True, capture_output=True, text=True, timeout=300, check=False)
    assert "Traceback" not in r.stderr and "BrokenPipe" not in r.stderr, r.stderr
    assert len(read_lifetimes(tmp_path / "o")) == 20


def test_10_dask_run_without_workers_fails_after_the_timeout(monkeypatch):
    distributed = pytest.importorskip("distributed")
    from hhscatter.run import runner

    class NoWorkers:  # a cluster whose last worker died: futures never finish
        def nthreads(self):
            return {}

        def submit(self, *a, **k):
            return object()

        def cancel(self, fs):
            self.cancelled = len(fs)

    def wait(fs, timeout=None, return_when=None):
        time.sleep(0.01)
        raise TimeoutError

    monkeypatch.setattr(distributed, "wait", wait)
    monkeypatch.setattr(runner, "DASK_NO_WORKER_TIMEOUT", 0.2)
    client = NoWorkers()
    task = runner.ChunkTask("{}", 0, 0, 10, "", "h")
    with pytest.raises(runner.RunError, match=r"the Dask cluster has had no workers for 0.2 s; stopped"):
        runner._run_dask(client, [task], lambda t: t, lambda *a: None, "x")
    assert client.cancelled == 1


# 11 -- a long snapshot grid is stored as its definition
def test_11_snapshot_grid_metadata_stays_small(tmp_path):
    d = {
        "energy": 0.3,
        "gamma": 0.01,
        "n": 50,
        "seed": 11,
        "chunk_size": 10,
        "t_max": 50.0,
        "snapshots": {"start": 0.0, "stop": 50.0, "step": 0.001},
    }
    scene = scene_from_dict(d)
    assert len(scene.snapshots) == 50001 and scene.snapshots[-1] == 50.0
    simulate(scene, tmp_path / "o", workers=1, progress=False)
    assert (tmp_path / "o" / "scene.json").stat().st_size < 3000
    meta = pq.read_schema(tmp_path / "o" / "snapshots" / "part-000000.parquet").metadata[b"hhscatter"]
    assert len(meta) < 3000 and json.loads(meta)["scene"]["snapshots"] == {"start": 0.0, "stop": 50.0, "step": 0.001}
    snaps = read_snapshots(tmp_path / "o")
    assert set(snaps.t) <= set(np.arange(0.0, 50.0005, 0.001))
    # a short grid (every study's) keeps its list, and its scene hash: the value computed on main (fb21563)
    short = scene_from_dict(
        {
            "energy": 0.3,
            "gamma": 0.01,
            "n": 500,
            "seed": 11,
            "chunk_size": 100,
            "snapshots": {"start": 0.0, "stop": 100.0, "step": 5.0},
            "sections": {},
        }
    )
    assert short.result_hash() == "1f6f2e0588e5210dc6b82997b9e53c9e409348268eb953294aa8bf563c7a835b"


# 12 -- the IC table is read and hashed once per run, not per chunk
def test_12_ic_table_is_hashed_once_per_run(tmp_path, monkeypatch):
    from hhscatter.scene import scene as scene_mod
    from hhscatter.scene.ics import region_ics

    ref = Scene(energy=0.3, n=60, seed=3, chunk_size=5)
    states = region_ics(ref, 0, ref.n)
    ics = tmp_path / "ics.parquet"
    pd.DataFrame(states, columns=["x", "y", "px", "py"]).to_parquet(ics)
    scene_mod._file_sha256.cache_clear()
    reads = []
    real = scene_mod._file_sha256.__wrapped__
    monkeypatch.setattr(
        scene_mod, "_file_sha256", scene_mod.functools.lru_cache(maxsize=64)(lambda *a: reads.append(a) or real(*a))
    )
    s = Scene(energy=None, n=60, ics=str(ics), chunk_size=5)
    simulate(s, tmp_path / "o", workers=1, progress=False)
    assert len(reads) == 1  # 12 chunks, one hash
    lt = read_lifetimes(tmp_path / "o")
    assert len(lt) == 60 and np.array_equal(lt[["x0", "y0", "px0", "py0"]].to_numpy(), states)


# 13 -- a run whose scene.json (its manifest) is gone is refused by every reader, not read as complete
def test_13_a_run_without_its_manifest_is_refused(run, capsys):
    from hhscatter.data.read import run_status

    (run / "scene.json").unlink()
    (run / "lifetimes" / "part-000003.parquet").unlink()  # one chunk gone with it: nothing could tell
    msg = r"the run at .*run has no scene.json, its manifest \(its parts say they belong to scene [0-9a-f]{12}…\)"
    for read in (read_lifetimes, read_sections, run_status):
        with pytest.raises(RunIntegrityError, match=msg):
            read(run)
    rc, err = _cli(capsys, "survival", str(run), "--png", str(run.parent / "p.png"))
    assert rc == 2 and "has no scene.json, its manifest" in err and not (run.parent / "p.png").exists()
    # the same simulate with --resume verifies the parts, redoes the missing chunk and writes the manifest again
    simulate(Scene(**SCENE), run, workers=1, progress=False, resume=True)
    assert len(read_lifetimes(run)) == SCENE["n"]


# 14 -- a file that is no Parquet file under a planned part's name: a named error, no traceback
def test_14_junk_under_a_part_name_is_refused(run, capsys):
    (run / "lifetimes" / "part-000001.parquet").write_text("junk")
    with pytest.raises(
        RunIntegrityError,
        match=r"a part of the lifetimes table of the run at .*run is not a readable "
        r"Parquet file .*part-000001.parquet.*rerun it with --resume",
    ):
        read_lifetimes(run)
    rc, err = _cli(capsys, "survival", str(run), "--png", str(run.parent / "p.png"))
    assert rc == 2 and "is not a readable Parquet file" in err


# 15 -- a run being written is not read piecemeal: finished chunks read apart would not match across tables
def test_15_partial_reads_of_a_run_being_written_are_refused(run):
    from hhscatter.data.store import Store

    (run / "lifetimes" / "part-000003.parquet").unlink()  # its last chunk not finished yet
    held = Store(run).lock()  # a writer at work
    try:
        with pytest.raises(
            IncompleteRunError,
            match=r"is incomplete: 1 of 4 chunk\(s\) .*and it is being written "
            r"now \(pid \d+\).*wait until the writer ends",
        ):
            read_lifetimes(run, allow_partial=True)
    finally:
        Store.unlock(held)
    with pytest.warns(UserWarning, match="reading the 300 orbits of the finished chunks"):
        lt = read_lifetimes(run, allow_partial=True)
    with pytest.warns(UserWarning):
        sec = read_sections(run, allow_partial=True)
    assert set(sec.traj_id) <= set(lt.traj_id)


# 16 -- an explicit list of snapshot times is not copied into every part's footer
def test_16_a_long_list_of_snapshot_times_stays_out_of_the_footers(tmp_path):
    times = [round(0.01 * k, 2) for k in range(1, 2001)]
    scene = Scene(energy=0.3, gamma=0.01, n=20, seed=1, chunk_size=10, t_max=50.0, snapshots=times)
    simulate(scene, tmp_path / "o", workers=1, progress=False)
    meta = json.loads(pq.read_schema(tmp_path / "o" / "lifetimes" / "part-000000.parquet").metadata[b"hhscatter"])
    assert meta["scene"]["snapshots"] == {
        "count": 2000,
        "first": 0.01,
        "last": 20.0,
        "sha256": hashlib.sha256(json.dumps(times).encode()).hexdigest(),
    }
    assert json.loads((tmp_path / "o" / "scene.json").read_text())["scene"]["snapshots"] == times  # kept once
    assert set(read_snapshots(tmp_path / "o").t) <= set(times)
