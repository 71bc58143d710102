"""Crash safety and resume: kill -9, damaged parts, full disk, refused resumes."""

import errno
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from hhscatter.cli import main
from hhscatter.data.read import verify_part
from hhscatter.errors import OutputError, RunError
from hhscatter.run.runner import simulate
from hhscatter.scene.scene import Scene, SectionWindow
from hhscatter.scene.schema import load_scene

TOML = """[scene]
energy = 0.3
gamma = 0.01
n = {n}
seed = 9
chunk_size = {chunk}
[sections]
t_from = 10.0
first_only = true
[snapshots]
times = [0.0, 5.0, 20.0]
"""


def _files(d):
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in sorted(Path(d).rglob("part-*.parquet"))}


def _temporaries(d):
    return [p for p in Path(d).rglob(".*") if ".tmp-" in p.name]


def _hh(*args, **kw):
    return [sys.executable, "-c", "import sys; from hhscatter.cli import main; sys.exit(main())", *args]


def test_kill_9_then_resume_equals_uninterrupted_run(tmp_path):
    n, chunk = 3000, 100
    (tmp_path / "k").mkdir()
    toml = tmp_path / "k" / "scene.toml"
    toml.write_text(TOML.format(n=n, chunk=chunk))
    scene = load_scene(toml)
    ref = tmp_path / "ref"
    simulate(scene, ref, workers=1, progress=False)
    reference = _files(ref)
    assert len(reference) == 3 * n // chunk

    out = tmp_path / "run"
    # a pool of 2 processes in its own session: kill -9 the whole group as soon as any chunk's part exists
    # (chunks finish in any order: a worker slow to compile can leave chunk 0 to the last)
    proc = subprocess.Popen(
        _hh("simulate", str(toml), "--out", str(out), "--workers", "2", "--quiet"),
        start_new_session=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    lifetimes = out / "lifetimes"
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if lifetimes.is_dir() and any(p.name.startswith("part-") for p in os.scandir(lifetimes)):
            break
        time.sleep(0.002)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run finished before it could be killed"
    done = len(list((out / "lifetimes").glob("part-*.parquet")))
    print(f"killed with {done} of {n // chunk} chunks done")
    assert 1 <= done < n // chunk
    # every part under its final name is complete
    for p in out.rglob("part-*.parquet"):
        verify_part(p)

    r = subprocess.run(
        _hh("simulate", str(toml), "--out", str(out), "--workers", "2", "--quiet", "--resume"),
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert r.returncode == 0, r.stderr
    assert "chunk(s) resumed" in r.stdout
    assert _files(out) == reference
    assert not _temporaries(out)


def test_damaged_parts_and_temporaries_are_redone(tmp_path):
    sc = Scene(
        energy=0.3, gamma=0.01, n=600, seed=3, chunk_size=150, sections=SectionWindow(t_from=5.0), snapshots=(0.0, 10.0)
    )
    out = tmp_path / "r"
    simulate(sc, out, workers=1, progress=False)
    before = _files(out)
    # 1: truncated lifetimes part; 2: one byte flipped inside a data page (footer intact: only the
    # page checksum can tell); 3: a sections part missing; plus a temporary left by a killed writer
    p1 = out / "lifetimes" / "part-000001.parquet"
    p1.write_bytes(p1.read_bytes()[: len(p1.read_bytes()) // 2])
    p2 = out / "lifetimes" / "part-000002.parquet"
    raw = bytearray(p2.read_bytes())
    raw[200] ^= 0xFF
    p2.write_bytes(bytes(raw))
    (out / "sections" / "part-000003.parquet").unlink()
    stale = out / "snapshots" / f".part-000000.parquet.tmp-{os.getpid() + 1}"
    stale.write_bytes(b"half a file")
    s = simulate(sc, out, workers=1, resume=True, progress=False)
    assert s.chunks_skipped == 1 and s.chunks_done == 3
    assert _files(out) == before
    assert not stale.exists()


def test_resume_of_another_scene_is_refused_and_names_the_difference(tmp_path, capsys):
    sc = Scene(energy=0.27, n=200, seed=3, chunk_size=100)
    out = tmp_path / "r"
    simulate(sc, out, workers=1, progress=False)
    before = _files(out)
    with pytest.raises(OutputError, match=r"different scene \(seed: 3 → 4\)"):
        simulate(sc.replace(seed=4), out, workers=1, resume=True, progress=False)
    rc = main(
        [
            "simulate",
            "--energy",
            "0.27",
            "-n",
            "200",
            "--seed",
            "3",
            "--chunk-size",
            "50",
            "--out",
            str(out),
            "--resume",
            "--quiet",
        ]
    )
    assert rc == 2 and "chunk_size: 100 → 50" in capsys.readouterr().err
    assert _files(out) == before


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EACCES])
def test_write_failure_is_clear_and_keeps_finished_parts(tmp_path, monkeypatch, code):
    import pyarrow.parquet as pq

    sc = Scene(energy=0.27, n=400, seed=2, chunk_size=100)
    ref = tmp_path / "ref"
    simulate(sc, ref, workers=1, progress=False)
    real, calls = pq.write_table, []

    def failing(table, where, **kw):
        calls.append(where)
        if len(calls) == 3:  # the third part file: a partial file, then the error, as a real full disk does
            if hasattr(where, "write"):  # local parts are written through an open file (hhscatter.data.write)
                where.write(b"PAR1 partial")
            else:
                Path(where).write_bytes(b"PAR1 partial")
            raise OSError(code, os.strerror(code))
        return real(table, where, **kw)

    monkeypatch.setattr(pq, "write_table", failing)
    out = tmp_path / "run"
    with pytest.raises(RunError) as info:
        simulate(sc, out, workers=1, progress=False)
    msg = str(info.value)
    assert os.strerror(code) in msg and "part-000002.parquet" in msg and "--resume" in msg
    assert _files(out) == {k: v for k, v in _files(ref).items() if k < "lifetimes/part-000002"}
    assert not _temporaries(out)
    monkeypatch.setattr(pq, "write_table", real)
    s = simulate(sc, out, workers=1, resume=True, progress=False)
    assert s.chunks_skipped == 2 and _files(out) == _files(ref)


def _can_mount_tmpfs(where):
    r = subprocess.run(
        ["unshare", "-rm", "sh", "-c", f"mount -t tmpfs -o size=64k tmpfs {where}"], capture_output=True, check=False
    )
    return r.returncode == 0


@pytest.mark.skipif(shutil.which("unshare") is None, reason="needs unshare (util-linux)")
def test_real_full_disk_on_a_tiny_tmpfs(tmp_path):
    """A real ENOSPC: a 96 kB tmpfs in a private mount namespace (no root needed: user namespace)."""
    mnt = tmp_path / "mnt"
    mnt.mkdir()
    if not _can_mount_tmpfs(mnt):
        pytest.skip("cannot mount a tmpfs in a user namespace here")
    sc_args = ["--energy", "0.27", "-n", "4000", "--seed", "6", "--chunk-size", "250", "--workers", "1", "--quiet"]
    keep = tmp_path / "kept"
    script = (
        f"mount -t tmpfs -o size=96k tmpfs {mnt} && "
        f"{sys.executable} -c 'import sys; from hhscatter.cli import main; sys.exit(main())' simulate "
        f"{' '.join(sc_args)} --out {mnt}/run; echo rc=$?; cp -a {mnt}/run {keep}"
    )
    r = subprocess.run(["unshare", "-rm", "sh", "-c", script], capture_output=True, text=True, timeout=300, check=False)
    assert "rc=1" in r.stdout, r.stdout + r.stderr
    assert "No space left on device" in r.stderr and "--resume" in r.stderr and "Traceback" not in r.stderr
    kept = _files(keep)
    assert 0 < len(kept) < 16
    for p in keep.rglob("part-*.parquet"):
        verify_part(p)
    assert not _temporaries(keep)
    # the same scene uninterrupted, named like the run (the name is in the metadata)
    (tmp_path / "ref").mkdir()
    assert main(["simulate", *sc_args, "--out", str(tmp_path / "ref" / "run")]) == 0
    reference = _files(tmp_path / "ref" / "run")
    assert all(kept[k] == reference[k] for k in kept)
    # resume where there is room (the name is the out folder's: resume into a folder called run)
    shutil.move(keep, tmp_path / "run")
    assert main(["simulate", *sc_args, "--out", str(tmp_path / "run"), "--resume"]) == 0
    assert _files(tmp_path / "run") == reference
