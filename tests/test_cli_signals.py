"""SIGINT and SIGTERM end every command with one line (what was kept, how to continue) and 130 / 143: no
traceback, no silent death. Each case waits for a sign that the command is at work (a file it writes), then
signals it, with bounded waits."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

STUDY_TOML = """[about]
title = "slow"
paper = ""
summary = "a study whose stages take long"

[scene]
energy = 0.3
n = 40000
t_max = 5000.0
chunk_size = 20000

[study]
x = 1
"""

STUDY_PY = """import time

from hhscatter.scene.schema import Integer
from hhscatter.studies.params import StudyParams


class Params(StudyParams):
    x: Integer


def simulate(study, workers=None, progress=True):
    study.run("long", study.scene("long"), workers=workers, progress=progress)


def analyze(study):
    (study.root / "ready").write_text("")
    import sympy  # noqa: F401  (an import in flight when the signal comes must not turn into another error)

    while True:
        time.sleep(0.05)


def plot(study):
    pass
"""


def _start(args, cwd):
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    return subprocess.Popen(
        [sys.executable, "-m", "hhscatter", *args],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _signal_when(proc, ready, sig, timeout=90.0):
    """Send ``sig`` once ``ready()`` holds (polled); the process's (returncode, stderr) within ``timeout``."""
    end = time.monotonic() + timeout
    while not ready():
        assert proc.poll() is None, f"ended before it was ready: {proc.communicate()}"
        assert time.monotonic() < end, "not ready in time"
        time.sleep(0.05)
    proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail(f"still running {timeout:g} s after {sig.name}")
    return proc.returncode, err


def _one_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err, err
    assert len(lines) == 1, err
    return lines[0]


def _study_folder(tmp_path) -> Path:
    folder = tmp_path / "studies" / "slow"
    folder.mkdir(parents=True)
    (folder / "study.toml").write_text(STUDY_TOML)
    (folder / "study.py").write_text(STUDY_PY)
    return folder


SIM = ["simulate", "--energy", "0.3", "-n", "40000", "--chunk-size", "20000", "--t-max", "5000", "--out", "run"]


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_simulate_interrupted_before_a_chunk_leaves_nothing(tmp_path, sig, code):
    proc = _start([*SIM, "--workers", "2"], tmp_path)
    rc, err = _signal_when(proc, lambda: (tmp_path / "run" / "scene.json").exists(), sig)
    assert rc == code
    line = _one_line(err)
    assert line.startswith(f"hhscatter: interrupted by {sig.name}; no chunk had finished"), line
    assert not (tmp_path / "run").exists()  # nothing left: the same command runs again without --overwrite


def test_simulate_interrupted_after_a_chunk_keeps_it_and_says_resume(tmp_path):
    args = ["simulate", "--energy", "0.3", "-n", "100000", "--chunk-size", "50", "--t-max", "5000"]
    proc = _start([*args, "--out", "run", "--workers", "1"], tmp_path)
    rc, err = _signal_when(proc, lambda: any((tmp_path / "run" / "lifetimes").glob("part-*")), signal.SIGINT)
    assert rc == 130
    assert "run the command again with --resume" in _one_line(err)
    assert (tmp_path / "run" / "scene.json").exists()


def test_study_analyze_interrupted_says_how_to_continue(tmp_path):
    folder = _study_folder(tmp_path)
    proc = _start(["study", "slow", "analyze", "--studies", str(folder.parent)], tmp_path)
    rc, err = _signal_when(proc, lambda: (folder / "ready").exists(), signal.SIGINT)
    assert rc == 130
    line = _one_line(err)
    assert "run `hhscatter study slow analyze --scale quick` again" in line and "--resume" not in line, line


def test_study_simulate_terminated_says_how_to_continue(tmp_path):
    folder = _study_folder(tmp_path)
    proc = _start(["study", "slow", "simulate", "--studies", str(folder.parent), "--workers", "2"], tmp_path)
    raw = folder / "out" / "quick" / "raw" / "long" / "scene.json"
    rc, err = _signal_when(proc, raw.exists, signal.SIGTERM)
    assert rc == 143
    line = _one_line(err)
    assert "run `hhscatter study slow simulate --scale quick` again" in line, line


def test_a_signal_whose_exception_is_lost_still_stops_the_run(tmp_path, monkeypatch):
    """A signal's exception raised where Python swallows it (a finaliser, a library's callback) must not let the
    run go on to its end: the run stops after the chunk it is in, the command ends with the signal's line and 130."""
    from hhscatter import cli
    from hhscatter.run import runner

    real = runner.run_one_chunk
    calls = []

    def chunk_where_the_signal_is_swallowed(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(2.0)  # the handler runs here and raises ...
            except KeyboardInterrupt:
                pass  # ... into code that swallows it
        return real(*args, **kwargs)

    monkeypatch.setattr(runner, "run_one_chunk", chunk_where_the_signal_is_swallowed)
    out = tmp_path / "run"
    args = ["simulate", "--energy", "0.3", "-n", "400", "--chunk-size", "50", "--t-max", "50", "--out", str(out)]
    rc = cli.main([*args, "--workers", "1"])
    assert rc == 130
    assert len(calls) == 2  # stopped after the chunk in which the signal came, not at the end (8 chunks)
    assert (out / "scene.json").exists()
