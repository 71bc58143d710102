"""The CLI as a new user meets it: python -m, --version, help, counts, --resume with only --out, section and
snapshot flags, survival of grid runs, errors without tracebacks, the closing summary, progress in logs."""

import json
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from hhscatter import __version__, read_lifetimes, read_sections, read_snapshots
from hhscatter.cli import build_parser, main


def _run(*args):
    return subprocess.run([sys.executable, "-m", "hhscatter", *args], capture_output=True, text=True, timeout=120)


def test_python_m_version_and_top_level_help():
    r = _run("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"hhscatter {__version__}"
    r = _run("--help")
    assert r.returncode == 0
    for cmd in ("simulate", "survival", "study"):
        assert f"\n    {cmd} " in r.stdout, cmd
    assert "``" not in r.stdout and ":func:" not in r.stdout  # no raw reStructuredText


@pytest.mark.parametrize("text,value", [("100000", 100000), ("1e5", 100000), ("2.0e3", 2000)])
def test_counts_accept_integral_floats(text, value):
    a = build_parser().parse_args(["simulate", "--energy", "0.3", "-n", text, "--chunk-size", text, "--out", "x"])
    assert a.n == value and a.chunk_size == value


@pytest.mark.parametrize("text", ["1.5", "1e-3", "nan", "inf", "ten"])
def test_counts_refuse_non_integral_values(text, capsys):
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(["simulate", "--energy", "0.3", "-n", text, "--out", "x"])
    assert exc.value.code == 2
    assert f"argument -n: not an integer: {text!r}" in capsys.readouterr().err


def test_resume_with_only_out_reads_the_scene_and_summary_tells(tmp_path, capsys):
    out = tmp_path / "g"
    assert (
        main(
            [
                "simulate",
                "--energy",
                "0.27,0.3",
                "--gamma",
                "0,0.01",
                "-n",
                "2e2",
                "--chunk-size",
                "100",
                "--seed",
                "4",
                "--out",
                str(out),
                "--workers",
                "1",
                "--sections-t-from",
                "3",
                "--sections-first-only",
                "--snapshots",
                "0:4:2",
            ]
        )
        == 0
    )
    first = capsys.readouterr().out
    before = {p: p.read_bytes() for p in out.rglob("part-*.parquet")}
    assert len(before) == 3 * 8
    # the closing summary: absolute path, rows per table, outcomes per grid point
    lt, sec, snap = read_lifetimes(out), read_sections(out), read_snapshots(out)
    assert f"wrote {out.resolve()}: lifetimes 800 rows, sections {len(sec)} rows, snapshots {len(snap)} rows" in first
    for (e, g), d in lt.groupby(["energy", "gamma"]):
        oc = d["outcome"].value_counts()
        line = (
            f"  E0={e:g}, γ={g:g}: escaped {oc.get('escaped', 0)}, settled {oc.get('settled', 0)}, "
            f"censored {oc.get('censored', 0)}"
        )
        assert line in first.splitlines(), line
    for p in list(before)[::5]:
        p.unlink()
    assert main(["simulate", "--out", str(out), "--resume", "--workers", "1"]) == 0
    again = capsys.readouterr().out
    assert "chunk(s) resumed" in again and "lifetimes 800 rows" in again
    assert {p: p.read_bytes() for p in out.rglob("part-*.parquet")} == before
    # a flag that changes the scene is still refused (names the key), without a traceback
    assert main(["simulate", "--out", str(out), "--resume", "-n", "300"]) == 2
    err = capsys.readouterr().err
    assert "different scene (n: 200 → 300)" in err and "Traceback" not in err


def test_resume_without_scene_json_says_so(tmp_path, capsys):
    assert main(["simulate", "--out", str(tmp_path / "none"), "--resume"]) == 2
    assert "--resume found no scene.json in --out" in capsys.readouterr().err


def test_section_and_snapshot_flags_override_the_scene_file(tmp_path):
    toml = tmp_path / "s.toml"
    toml.write_text(
        "[scene]\nenergy = 0.3\ngamma = 0.01\nn = 60\nseed = 2\n[sections]\nt_from = 1.0\n"
        "[snapshots]\ntimes = [0.0, 1.0]\n"
    )
    out = tmp_path / "o"
    assert (
        main(
            [
                "simulate",
                str(toml),
                "--out",
                str(out),
                "--workers",
                "1",
                "--sections-t-to",
                "8",
                "--sections-e-max",
                "0.29",
                "--sections-first-only",
                "--snapshots",
                "0,2.5,5",
            ]
        )
        == 0
    )
    scene = json.loads((out / "scene.json").read_text())["scene"]
    assert scene["sections"] == {"t_from": 1.0, "t_to": 8.0, "e_min": "-inf", "e_max": 0.29, "first_only": True}
    assert scene["snapshots"] == [0.0, 2.5, 5.0]
    sec = read_sections(out)
    assert len(sec) and sec["t"].between(1.0, 8.0).all() and (sec["energy"] <= 0.29).all()
    assert not sec["traj_id"].duplicated().any()
    assert set(read_snapshots(out)["t"]) <= {0.0, 2.5, 5.0}


def test_survival_of_a_grid_run_draws_one_curve_per_point(tmp_path, capsys):
    out = tmp_path / "g"
    assert main(["simulate", "--energy", "0.27,0.3", "-n", "100", "--out", str(out), "--workers", "1"]) == 0
    capsys.readouterr()
    png = tmp_path / "p.png"
    assert main(["survival", str(out), "--png", str(png)]) == 0
    assert "(2 curves)" in capsys.readouterr().out and png.stat().st_size > 10_000
    assert main(["survival", str(out), "--png", str(png), "--labels", "only one"]) == 2
    assert "1 label(s) for 2 curve(s)" in capsys.readouterr().err


def test_survival_reads_no_whole_table(tmp_path, capsys, monkeypatch):
    """The command checks the run on one column and hands the run directory to survival (read part by part, the
    columns P(t) needs): no reader is asked for every column of the lifetimes table."""
    import hhscatter.data.read as read

    out = tmp_path / "r"
    assert main(["simulate", "--energy", "0.3", "-n", "100", "--out", str(out), "--workers", "1"]) == 0
    asked = []
    real = read.read_lifetimes

    def spy(run, *args, **kwargs):
        asked.append(kwargs.get("columns"))
        return real(run, *args, **kwargs)

    monkeypatch.setattr(read, "read_lifetimes", spy)
    capsys.readouterr()
    assert main(["survival", str(out), "--png", str(tmp_path / "p.png")]) == 0
    assert "(1 curve)" in capsys.readouterr().out
    assert asked and None not in asked, asked


@pytest.mark.parametrize(
    "args,message",
    [
        (["survival", "{tmp}/missing", "--png", "{tmp}/p.png"], "does not exist"),
        (["survival", "{tmp}", "--png", "{tmp}/p.png"], "no lifetimes table"),
        (["survival", "{tmp}", "--png", "{tmp}/no/such/dir/p.png"], "--png: folder"),
        (["study", "fig6", "analyze", "--scale", "nosuchscale"], "scale"),
    ],
)
def test_user_errors_exit_2_without_traceback(tmp_path, args, message):
    """A missing run, an empty folder, a --png folder that does not exist: message, status 2, no traceback."""
    r = _run(*[a.format(tmp=tmp_path) for a in args])
    assert r.returncode == 2 and message in r.stderr and "Traceback" not in r.stderr


def test_progress_is_off_in_logs_unless_asked_and_then_plain(tmp_path):
    base = ["simulate", "--energy", "0.3", "-n", "40", "--chunk-size", "20", "--workers", "1"]
    quiet = _run(*base, "--out", str(tmp_path / "a"))  # stderr is a pipe: no progress at all
    assert quiet.returncode == 0 and quiet.stderr == ""
    asked = _run(*base, "--out", str(tmp_path / "b"), "--progress")
    assert asked.returncode == 0 and "\r" not in asked.stderr
    assert asked.stderr.strip().splitlines()[-1].startswith("b: 40/40 orbits (100 %)")
    off = _run(*base, "--out", str(tmp_path / "c"), "--no-progress")
    assert off.returncode == 0 and off.stderr == ""


def test_study_stages_say_what_they_wrote(tmp_path, monkeypatch, capsys):
    import hhscatter.studies as studies

    (tmp_path / "fake").mkdir()
    (tmp_path / "fake" / "study.toml").write_text("[scene]\nenergy = 0.3\nn = 10\n[study]\nx = 1\n")

    def analyze(study):
        study.write_numbers({"x": 1})
        study.derived("t.parquet").write_bytes(b"")

    fake = types.SimpleNamespace(
        simulate=lambda study, workers=None, progress=True: None,
        analyze=analyze,
        plot=lambda study: study.figure_path.write_bytes(np.zeros(4).tobytes()),
    )
    monkeypatch.setattr(studies, "stage_module", lambda name, root=None: fake)
    studies.run_stage("fake", "all", "quick", root=tmp_path)
    out = capsys.readouterr().out.splitlines()
    where = tmp_path / "fake" / "out" / "quick"
    assert out == [
        f"fake simulate: raw runs in {where / 'raw'}",
        f"fake analyze: wrote {where / 'fake.json'} and 1 derived table(s) in {where / 'derived'}",
        f"fake plot: wrote {where / 'fake.png'}",
    ]


@pytest.mark.parametrize(
    "argv, hint",
    [
        (
            ["simulate", "--energy", "0.3", "--wokers", "2", "--out", "x"],
            "unrecognized arguments: --wokers; did you mean '--workers'?",
        ),
        (["study", "fig2", "analyse"], "did you mean 'analyze'?"),
        (["simulat"], "did you mean 'simulate'?"),
    ],
)
def test_a_mistyped_flag_or_choice_gets_a_suggestion(argv, hint, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2 and hint in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_study_help_lists_the_studies_and_a_mistyped_name_is_answered(capsys, tmp_path, monkeypatch):
    from hhscatter.studies.graph import studies

    with pytest.raises(SystemExit):
        main(["study", "--help"])
    out = capsys.readouterr().out
    names = [s.name for s in studies()]
    assert "fig2" in names and all(f"\n  {n} " in out for n in names)
    monkeypatch.chdir(tmp_path)  # elsewhere, the studies folder named explicitly
    assert main(["study", "fgi2", "plot", "--studies", str(Path(__file__).resolve().parents[1] / "studies")]) == 2
    assert "got 'fgi2' (did you mean 'fig2'?)" in capsys.readouterr().err


def test_scene_takes_an_integral_float_count_like_the_cli():
    from hhscatter import Scene, SceneError

    s = Scene(energy=0.3, n=2e4, seed=1.0)
    assert s.n == 20000 and type(s.n) is int and s.result_hash() == Scene(energy=0.3, n=20000, seed=1).result_hash()
    for bad in (2.5, float("nan"), float("inf")):
        with pytest.raises(SceneError, match="n \\(number of orbits\\) must be an integer > 0"):
            Scene(energy=0.3, n=bad)


def test_the_command_starts_without_loading_the_study_framework():
    """Every command's parser lists the studies (graph.py, stdlib only) without importing hhscatter.studies, the
    runner, the tables or pydantic (≈ 0.25 s of start-up for every `hhscatter` call)."""
    import subprocess
    import sys

    code = (
        "import sys, hhscatter.cli as c; c.build_parser(); "
        "print(sorted(m for m in ('hhscatter.studies', 'hhscatter.run.runner', 'hhscatter.data.read', 'pydantic', "
        "'pyarrow', 'heyoka') if m in sys.modules)); print('fig1' in c._studies_epilog())"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "[]" and out[1] == "True", out


def test_the_command_help_starts_without_the_system_registry():
    """The --system help reads the built-ins' names only when shown: `hhscatter --help` loads neither the
    registry nor sympy."""
    import subprocess
    import sys

    code = (
        "import contextlib, io, sys, hhscatter.cli as c\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        "    c.main(['--help'])\n"
        "print(sorted(m for m in ('hhscatter.model.builtins', 'sympy') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", out


SIM = ["simulate", "--energy", "0.3", "-n", "10", "--t-max", "20", "--workers", "1", "--quiet"]


@pytest.mark.parametrize(
    "args,message",
    [
        (SIM + ["--system", "", "--out", "{tmp}/o"], "--system must not be empty, got ''"),
        (["simulate", "--ics", "", "--out", "{tmp}/o"], "--ics must not be empty, got ''"),
        (SIM + ["--out", ""], "--out must not be empty, got '' (name the working directory as '.')"),
        (SIM + ["--scale", " ", "--out", "{tmp}/o"], "--scale must not be empty, got ' '"),
        (SIM + ["--scheduler", "", "--out", "{tmp}/o"], "--scheduler must not be empty, got ''"),
        (
            SIM + ["--system", "contopoulos", "--param", "eps=0.25", "--param", "eps=0.3", "--out", "{tmp}/o"],
            "--param eps given 2 times (0.25, 0.3): give each parameter once",
        ),
        (
            ["simulate", "--ics", "{tmp}/ics.csv", "--region", "square", "--out", "{tmp}/o"],
            "--region is for initial conditions sampled in a region; with --ics the table gives every initial state",
        ),
        (
            ["simulate", "--ics", "{tmp}/ics.csv", "--radius", "0.3", "--region", "disk", "--out", "{tmp}/o"],
            "--region and --radius are for initial conditions sampled in a region",
        ),
        (SIM + ["--sections-e-min", "0.5", "--out", "{tmp}/o"], "sections.e_min = 0.5 is above E0 = 0.3"),
    ],
)
def test_empty_repeated_and_ignored_inputs_are_refused(tmp_path, monkeypatch, capsys, args, message):
    """An empty shell variable is not the default; a flag given twice or one that would be ignored is an error."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "ics.csv").write_text("x,y,px,py\n0.1,0.05,0.6,0.1\n")
    assert main([a.format(tmp=tmp_path) for a in args]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ics.csv"]  # nothing written


def test_minus_zero_gamma_is_the_conservative_scene(tmp_path, capsys):
    assert main(SIM + ["--gamma", "-0", "--out", str(tmp_path / "m")]) == 0
    out = capsys.readouterr().out
    assert "γ=0:" in out and "γ=-0" not in out
    assert main(SIM + ["--gamma", "0", "--out", str(tmp_path / "m"), "--resume"]) == 0  # the same scene
    assert "nothing to do: all 1 chunk(s) verified complete" in capsys.readouterr().out
