"""The system flags of ``hhscatter simulate``: --system, --param, --dissipation."""

import json

import pyarrow.parquet as pq
import pytest

from hhscatter.cli import main
from hhscatter.model.builtins import BUILTINS


def _cli(capsys, *args):
    rc = main(list(args))
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return rc, err


def _meta(out):
    part = sorted(out.glob("lifetimes/**/*.parquet"))[0]
    return json.loads(pq.read_schema(part).metadata[b"hhscatter"])


def test_henon_heiles_by_name_writes_the_tables_of_the_default(tmp_path, capsys):
    """--system henon_heiles --param lam=1 is the default system: same hash, same bytes, no system in the metadata."""
    base = ["simulate", "--energy", "0.3", "-n", "40", "--workers", "1", "--quiet", "--t-max", "200"]
    assert _cli(capsys, *base, "--out", str(tmp_path / "a"))[0] == 0
    assert _cli(capsys, *base, "--system", "henon_heiles", "--param", "lam=1", "--out", str(tmp_path / "b"))[0] == 0
    a, b = _meta(tmp_path / "a"), _meta(tmp_path / "b")
    assert a["scene_hash"] == b["scene_hash"] and "system" not in b
    pa = sorted((tmp_path / "a").glob("lifetimes/**/*.parquet"))[0]
    pb = sorted((tmp_path / "b").glob("lifetimes/**/*.parquet"))[0]
    assert pq.read_table(pa).equals(pq.read_table(pb))


def test_quadratic_drag_is_recorded_in_the_metadata(tmp_path, capsys):
    out = tmp_path / "q"
    rc, _ = _cli(
        capsys,
        "simulate",
        "--energy",
        "0.3",
        "--gamma",
        "0.01",
        "-n",
        "20",
        "--workers",
        "1",
        "--quiet",
        "--dissipation",
        "quadratic",
        "--out",
        str(out),
    )
    assert rc == 0
    m = _meta(out)
    assert m["scene"]["system"]["dissipation"] == "quadratic"
    assert m["system"] == {
        "system": "henon_heiles",
        "potential": "0.5*omega**2*(x**2 + y**2) + lam*(x**2*y - y**3/3)",
        "params": {"omega": 1.0, "lam": 1.0},
        "dissipation": "quadratic",
    }


@pytest.mark.parametrize(
    "flags, message",
    [
        (["--param", "eps"], "param: expected NAME=VALUE, got 'eps'"),
        (["--param", "eps=big"], "argument --param: not a number: 'big'"),
        (["--dissipation", "cubic"], "invalid choice: 'cubic'"),
    ],
)
def test_malformed_system_flags_exit_2(tmp_path, capsys, flags, message):
    out = tmp_path / "o"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "--energy", "0.3", "-n", "10", *flags, "--out", str(out)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and message in err and "Traceback" not in err, err
    assert not out.exists()


def test_unknown_parameter_of_a_built_in_exits_2_before_any_work(tmp_path, capsys):
    out = tmp_path / "o"
    rc, err = _cli(
        capsys,
        "simulate",
        "--energy",
        "0.3",
        "-n",
        "10",
        "--system",
        "henon_heiles",
        "--param",
        "mu=2",
        "--out",
        str(out),
    )
    assert rc == 2 and "henon_heiles has parameters ['lam', 'omega'], got ['mu']" in err, err
    assert not out.exists()


@pytest.mark.parametrize(
    "system, params, energy, message",
    [
        ("0.5*(x**2 + y**2) - eps*x**2*z", ["eps=0.25"], "1.5", "z"),  # unknown symbol
        ("0.5*(x**2 + y**2) - eps*foo(x)*y**2", ["eps=0.25"], "1.5", "foo"),  # unknown function
        ("0.5*(x**2 + y**2) - eps*x**2*y**2", [], "1.5", "eps"),  # missing parameter
        ("0.5*(x**2 + y**2)", [], "1.5", "exit"),  # no exit
        ("0.5*((x - 1)**2 + y**2) - 0.1*x**3", [], "1.5", "origin"),  # well not at the origin
        ("0.5*(x**2 + y**2) - eps*x**2*y**2", ["eps=0.25"], "0.5", "energy must be > E_c = 1"),  # E0 below E_c
        ("__import__('os').system('echo hacked')", [], "1.5", "__import__"),  # never evaluated
    ],
)
def test_bad_declared_systems_exit_2_naming_the_problem(tmp_path, capsys, system, params, energy, message):
    out = tmp_path / "o"
    flags = [x for p in params for x in ("--param", p)]
    rc, err = _cli(capsys, "simulate", "--energy", energy, "-n", "10", "--system", system, *flags, "--out", str(out))
    assert rc == 2 and message in err, err
    assert not out.exists()


def test_declared_potential_runs_end_to_end_from_a_scene_file(tmp_path, capsys):
    """A scene file with [system] potential = … runs and names its system in the tables."""
    f = tmp_path / "scene.toml"
    f.write_text(
        "[scene]\nenergy = 1.5\nn = 50\nt_max = 300\n[system]\n"
        'potential = "0.5*(x**2 + y**2) - eps*x**2*y**2"\n[system.params]\neps = 0.25\n'
    )
    out = tmp_path / "run"
    rc, _ = _cli(capsys, "simulate", str(f), "--workers", "1", "--quiet", "--out", str(out))
    assert rc == 0
    m = _meta(out)
    assert m["system"]["potential"] == "0.5*(x**2 + y**2) - eps*x**2*y**2" and m["system"]["params"] == {"eps": 0.25}
    import pandas as pd

    lt = pd.read_parquet(out / "lifetimes")
    esc = lt[lt["outcome"] == "escaped"]
    assert len(esc) > 25 and set(esc["exit_channel"].astype(int)) <= {0, 1, 2, 3}


def test_the_system_help_names_every_builtin_of_the_registry(capsys, monkeypatch):
    monkeypatch.setitem(BUILTINS, "quartic_toy", BUILTINS["barbanis"])
    with pytest.raises(SystemExit) as e:
        main(["simulate", "--help"])
    assert e.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"a built-in ({', '.join(BUILTINS)}) or a potential V" in text
    assert "quartic_toy" in text
