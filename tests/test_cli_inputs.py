"""Inputs the CLI refuses with one line, exit 2 and nothing written, or takes with a clear word: snapshot grids
beyond the float range, systems at extreme scales, section windows that can record nothing, output names that
are not PNG files, more workers than CPUs."""

from __future__ import annotations

import re

import pytest

from hhscatter.cli import main
from hhscatter.run.worker import default_workers

SIM = ["simulate", "--energy", "0.3", "-n", "10", "--t-max", "5"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--snapshots", "0:1e300:1e-300"], "snapshots: 0:1e+300:1e-300 gives inf times, more than 100000"),
        (["--snapshots", "0:5:1e-300"], "snapshots: 0:5:1e-300 gives 5e+300 times"),
        (["--snapshots", "0:5:1e-6"], "snapshots: 0:5:1e-06 gives 5000001 times"),
        (["--system", "henon_heiles", "--param", "lam=1e-300"], "lam = 1e-300 give E_c = ω⁶/(6λ²) = inf, outside"),
        (["--param", "lam=1e-300"], "lam = 1e-300 give E_c = ω⁶/(6λ²) = inf, outside"),
        (["--system", "henon_heiles", "--param", "omega=1e-30"], "give E_c = ω⁶/(6λ²) = 1.67e-181, outside"),
        (["--sections-t-from", "6"], "sections.t_from = 6 is not before t_max = 5"),
        (["--sections-t-from", "5"], "sections.t_from = 5 is not before t_max = 5"),
        (["--sections-e-max", "0.2"], "sections.e_max = 0.2 is below E0 = 0.3: without drag the energy stays E0"),
        (
            ["--gamma", "0.01", "--sections-e-max", "0.1"],
            "sections.e_max = 0.1 is below E_c = 0.1666666667: an orbit settles (and ends) when its energy falls",
        ),
    ],
)
def test_simulate_refuses_with_one_line_and_writes_nothing(tmp_path, capsys, args, message):
    assert main([*SIM, *args, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_section_windows_that_can_record_are_taken(tmp_path, capsys):
    """The mirrors of the refused windows: e_max at E0 without drag, e_max between E_c and E0 with drag."""
    assert main([*SIM, "--sections-e-max", "0.3", "--sections-t-from", "4", "--out", str(tmp_path / "a")]) == 0
    assert main([*SIM, "--gamma", "0.01", "--sections-e-max", "0.2", "--out", str(tmp_path / "b")]) == 0


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs") / "r"
    assert main([*SIM, "--out", str(out), "--workers", "1"]) == 0
    return out


@pytest.mark.parametrize("png", ["x.txt", "x", "x.pdf"])
def test_survival_png_must_name_a_png_file(tmp_path, monkeypatch, capsys, small_run, png):
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert main(["survival", str(small_run), "--png", png]) == 2
    err = capsys.readouterr().err
    assert f"--png must name a .png file, got {png!r}" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_survival_writes_the_file_it_names(tmp_path, capsys, small_run):
    assert main(["survival", str(small_run), "--png", str(tmp_path / "p.PNG")]) == 0
    assert f"wrote {tmp_path / 'p.PNG'}" in capsys.readouterr().out
    assert [p.name for p in tmp_path.iterdir()] == ["p.PNG"]


def test_more_workers_than_cpus_run_as_many_as_there_are_and_say_so(tmp_path, capsys):
    cpus = default_workers()
    args = ["simulate", "--energy", "0.3", "-n", "40", "--chunk-size", "10", "--t-max", "5"]
    assert main([*args, "--workers", "1000", "--out", str(tmp_path / "o")]) == 0
    cap = capsys.readouterr()
    assert (
        f"--workers 1000 is more than the {cpus} CPU(s) this process may use: {cpus} worker process(es) run" in cap.err
    )
    assert re.search(rf"\({cpus} workers?\)", cap.out), cap.out
