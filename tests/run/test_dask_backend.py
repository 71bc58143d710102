"""Dask backend: the same bytes as the local pool, on a real LocalCluster (separate worker processes)."""

import pytest

from hhscatter.cli import main
from hhscatter.errors import OutputError, SetupError
from hhscatter.run.runner import simulate
from hhscatter.scene.scene import Noise, Scene, SectionWindow

distributed = pytest.importorskip("distributed")


def _files(d):
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in sorted(d.rglob("part-*.parquet"))}


@pytest.fixture(scope="module")
def cluster():
    """A LocalCluster of 2 single-threaded worker processes, reached through its tcp:// address."""
    import logging

    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
    ) as c:
        yield c


@pytest.fixture(scope="module")
def scene():
    # all three tables, 3 chunks; section and snapshot times depend on chunk_size in the last
    # bits (absolute lane times), so every backend must use the same chunk_size: it is part of the scene
    return Scene(
        energy=0.3,
        gamma=0.01,
        n=450,
        seed=21,
        chunk_size=150,
        sections=SectionWindow(t_from=5.0, first_only=True),
        snapshots=(0.0, 5.0, 20.0),
    )


@pytest.fixture(scope="module")
def reference(tmp_path_factory, scene):
    out = tmp_path_factory.mktemp("ref") / "w1"
    simulate(scene, out, workers=1, progress=False)
    return _files(out)


def test_dask_cluster_equals_local_pool_byte_for_byte(tmp_path, scene, reference, cluster):
    from distributed import Client

    assert len(reference) == 9
    pool = tmp_path / "pool2"
    simulate(scene, pool, workers=2, progress=False)
    assert _files(pool) == reference
    # an existing cluster by address: the tasks run in the 2 worker processes
    out = tmp_path / "dask2"
    from distributed import get_task_stream

    with Client(cluster) as client, get_task_stream(client) as ts:
        s = simulate(scene, out, scheduler=cluster.scheduler_address, progress=False)
    ran = [t for t in ts.data if str(t["key"]).startswith("hhscatter-")]
    assert len(ran) == 3 and all(t["worker"] in cluster.scheduler_info["workers"] for t in ran)
    assert s.workers == 2 and s.backend.startswith("dask tcp://") and s.chunks_done == 3
    assert _files(out) == reference
    # the cluster's workers are separate processes
    import os

    with Client(cluster) as client:
        worker_pids = set(client.run(os.getpid).values())
    assert os.getpid() not in worker_pids and len(worker_pids) == 2
    # one worker: same bytes again
    cluster.scale(1)
    import time

    deadline = time.monotonic() + 60
    with Client(cluster) as client:
        while len(client.nthreads()) != 1 and time.monotonic() < deadline:
            time.sleep(0.05)
    out1 = tmp_path / "dask1"
    s = simulate(scene, out1, scheduler=cluster.scheduler_address, progress=False)
    assert s.workers == 1 and _files(out1) == reference
    cluster.scale(2)


def test_cli_scheduler_local_grid(tmp_path, capsys):
    """`--scheduler local` starts its own LocalCluster; a grid run gives the pool's bytes."""
    args = [
        "simulate",
        "--energy",
        "0.25,0.3",
        "--gamma",
        "0.005,0.01",
        "-n",
        "120",
        "--chunk-size",
        "60",
        "--seed",
        "4",
        "--quiet",
    ]
    assert main([*args, "--out", str(tmp_path / "g"), "--workers", "1"]) == 0
    capsys.readouterr()
    # same out name (it is the scene name, stored in the metadata) in another folder
    (tmp_path / "d").mkdir()
    assert main([*args, "--out", str(tmp_path / "d" / "g"), "--workers", "2", "--scheduler", "local"]) == 0
    assert "dask LocalCluster" in capsys.readouterr().out
    a, b = _files(tmp_path / "g"), _files(tmp_path / "d" / "g")
    assert len(a) == 8 and a == b


@pytest.mark.parametrize(
    "args,message",
    [
        (["--scheduler", "nowhere"], "scheduler must be 'local' or an address"),
        (["--scheduler", "tcp://127.0.0.1:8786", "--workers", "2"], "workers: the number of workers is the cluster's"),
    ],
)
def test_bad_scheduler_fails_before_work(tmp_path, capsys, args, message):
    out = tmp_path / "never"
    assert main(["simulate", "--energy", "0.3", "-n", "10", "--out", str(out), "--quiet", *args]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_missing_dask_is_a_clear_error(tmp_path, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_dask(name, *a, **k):
        if name == "distributed" or name.startswith("distributed."):
            raise ImportError("no dask here")
        return real(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", no_dask)
    with pytest.raises(SetupError, match=r"pip install 'hhscatter\[dask\]'"):
        simulate(Scene(energy=0.3, n=10), tmp_path / "o", scheduler="local", progress=False)
    assert not (tmp_path / "o").exists()


def test_fsspec_url_output_resume_and_read(tmp_path, scene, reference):
    """A URL --out goes through pyarrow.fs/fsspec (here fsspec's in-memory filesystem, this process only)."""
    import fsspec

    from hhscatter.data.read import read_lifetimes, read_sections

    url = "memory://hhscatter-test/run"
    try:
        simulate(scene, url, workers=1, progress=False)
        fs = fsspec.filesystem("memory")
        got = {
            p.split("/run/", 1)[1]: fs.cat(p)
            for p in fs.find("/hhscatter-test/run")
            if p.rsplit("/", 1)[-1].startswith("part-")
        }
        assert got == reference
        fs.rm("/hhscatter-test/run/lifetimes/part-000001.parquet")
        s = simulate(scene, url, workers=1, resume=True, progress=False)
        assert s.chunks_skipped == 2 and s.chunks_done == 1
        for rel, data in reference.items():  # the reference bytes as a local run, read the same way
            (tmp_path / "local" / rel).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / "local" / rel).write_bytes(data)
        (tmp_path / "local" / "scene.json").write_bytes(fs.cat("/hhscatter-test/run/scene.json"))  # its manifest
        lt = read_lifetimes(url)
        assert len(lt) == 450 and lt.equals(read_lifetimes(tmp_path / "local"))
        assert len(read_sections(url)) > 0
        with pytest.raises(OutputError, match="not empty"):
            simulate(scene, url, workers=1, progress=False)
    finally:
        fsspec.filesystem("memory").rm("/hhscatter-test", recursive=True)


@pytest.mark.parametrize(
    "gamma, noise",
    [
        (1.0, {"temperature": 1 / 12, "flow": "symplectic"}),
        (0.0, {"sigma": 0.04, "flow": "symplectic"}),
        (1.0, {"temperature": 1 / 12, "flow": "taylor"}),
    ],
    ids=["heat-bath-compiled", "noise-alone-compiled", "heat-bath-taylor"],
)
def test_noise_runs_on_a_dask_cluster_equal_the_local_pool_byte_for_byte(tmp_path, cluster, gamma, noise):
    """The noise path keeps the backend's promise: per-orbit random streams give the same tables on a Dask cluster
    as on one local worker (three chunks, two worker processes)."""
    sc = Scene(energy=0.16, n=240, gamma=gamma, t_max=30.0, seed=4, chunk_size=80, noise=Noise(**noise))
    ref = tmp_path / "local1"
    simulate(sc, ref, workers=1, progress=False)
    out = tmp_path / "dask"
    s = simulate(sc, out, scheduler=cluster.scheduler_address, progress=False)
    assert s.backend.startswith("dask tcp://") and s.chunks_done == 3
    reference = _files(ref)
    assert len(reference) >= 3 and _files(out) == reference
