"""Command line: ``hhscatter simulate`` and ``hhscatter survival``.

Exit status: 0 on success, 2 on bad input (the message names the parameter and
its allowed range; nothing has been computed), 1 on other failures.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path


def _float(s):
    try:
        return float(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {s!r}") from None


def _floats(s):
    """One number, or a comma-separated list of numbers (a grid axis)."""
    if "," not in s:
        return _float(s)
    return [_float(x.strip()) for x in s.split(",") if x.strip()]


def _int(s):
    try:
        return int(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {s!r}") from None


def build_parser():
    p = argparse.ArgumentParser(prog="hhscatter", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser(
        "simulate",
        help="integrate an ensemble and write Parquet tables",
        description="Integrate an ensemble of Hénon–Heiles orbits (exact event times) and write "
        "the lifetimes (and, if asked, sections/snapshots) tables as Parquet datasets.",
    )
    s.add_argument("scene", nargs="?", help="scene TOML file (flags below override its values)")
    s.add_argument("--scale", help="named scale in the scene file, e.g. 'paper' (default: quick)")
    s.add_argument("--energy", type=_floats,
                   help="initial energy E0 (> E_c = 1/6 for ω=λ=1); a list 0.25,0.3 makes a grid run")
    s.add_argument("--gamma", type=_floats, help="drag γ ≥ 0 (0 = conservative); a list 0,0.01 makes a grid run")
    s.add_argument("-n", type=_int, help="number of orbits N > 0")
    s.add_argument("--seed", type=_int, help="seed ≥ 0 (with the orbit index it fixes every orbit)")
    s.add_argument("--region", choices=["disk", "well"], help="initial-condition region")
    s.add_argument("--radius", type=_float, help="disk radius (default 0.5)")
    s.add_argument("--r-esc", type=_float, dest="r_esc", help="escape radius (default 1.5; the paper used 1.03, see study resc)")
    s.add_argument("--t-max", type=_float, dest="t_max", help="maximum orbit time (default 5000)")
    s.add_argument("--tol", type=_float, help="integrator tolerance in [1e-18, 1e-6] (default 1e-15)")
    s.add_argument("--chunk-size", type=_int, dest="chunk_size", help="orbits per part file (default 10000)")
    s.add_argument("--batch-size", type=_int, dest="batch_size", help="SIMD lanes (default: heyoka's choice)")
    s.add_argument("--ics", help="Parquet/CSV table of initial states with columns x, y, px, py [, traj_id]")
    s.add_argument("--out", required=True, help="output directory, or a URL pyarrow/fsspec can write (s3://…)")
    s.add_argument("--workers", type=_int, help="worker processes (default: all cores)")
    s.add_argument("--scheduler", help="run the chunks on Dask: 'local' (a LocalCluster of --workers processes) "
                   "or a scheduler address tcp://HOST:PORT (needs the 'dask' extra)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--overwrite", action="store_true", help="replace the tables in a non-empty --out")
    g.add_argument("--resume", action="store_true", help="keep verified finished chunks in --out, redo the rest")
    s.add_argument("--quiet", action="store_true", help="no progress bar")

    v = sub.add_parser("survival", help="plot P(t) of one or more runs to a PNG")
    v.add_argument("runs", nargs="+", help="run directories (outputs of simulate)")
    v.add_argument("--png", required=True, help="output PNG path")
    v.add_argument("--labels", nargs="*", help="curve labels (default: from the scenes)")

    st = sub.add_parser(
        "study",
        help="run one stage of a study (simulate → analyze → plot)",
        description="Run a stage of a study in studies/<name>/: 'simulate' writes raw Parquet runs, "
        "'analyze' derived tables and <name>.json, 'plot' <name>.png; 'all' runs the three.",
    )
    st.add_argument("name", help="study name (a folder of studies/ with a study.toml), e.g. fig2")
    st.add_argument("stage", choices=["simulate", "analyze", "plot", "all"])
    st.add_argument("--scale", default="quick", help="'quick' (default), 'paper', or another scale in study.toml")
    st.add_argument("--workers", type=_int, help="worker processes (default: all cores)")
    st.add_argument("--quiet", action="store_true", help="no progress bars")
    return p


def _scene_from_args(a):
    """The Scene (or, when --energy/--gamma or the file give lists, the Grid) of the simulate flags."""
    from .grid import load_run, run_from_dict
    from .scene import SceneError

    flags = {
        k: getattr(a, k)
        for k in ("energy", "gamma", "n", "seed", "region", "radius", "r_esc", "t_max", "tol", "chunk_size",
                  "batch_size")
    }
    for k, v in flags.items():
        for x in v if isinstance(v, list) else [v]:
            if isinstance(x, float) and not math.isfinite(x):
                raise SceneError(f"{k.replace('_', '-')} must be finite, got {x}")
    if a.ics:
        from .ics import read_ics_table

        states, _ = read_ics_table(a.ics)
        if flags["n"] is not None and flags["n"] != len(states):
            raise SceneError(f"n = {flags['n']} but the ics table has {len(states)} rows")
        flags["n"] = len(states)
        flags["ics"] = str(Path(a.ics).resolve())
    if a.scene:
        return load_run(a.scene, scale=a.scale, **flags)
    if a.scale:
        raise SceneError("--scale needs a scene file")
    d = {k: v for k, v in flags.items() if v is not None}
    d.setdefault("name", Path(a.out).name)
    if "n" not in d:
        raise SceneError("n (number of orbits) is required: give -n or a scene file")
    if "energy" not in d and not a.ics:
        raise SceneError("energy is required: give --energy or a scene file")
    return run_from_dict(d)


def cmd_simulate(a):
    from .runner import simulate

    scene = _scene_from_args(a)
    summary = simulate(scene, a.out, workers=a.workers, overwrite=a.overwrite, resume=a.resume,
                       progress=not a.quiet, scheduler=a.scheduler)
    print(summary.line())
    return 0


def cmd_survival(a):
    import json

    from .analysis.survival import observed_from_outcome, survival_curve
    from .plotting import plot_survival
    from .tables import read_lifetimes

    curves = []
    for i, run in enumerate(a.runs):
        df = read_lifetimes(run, columns=["outcome", "t_end"])
        t, P, err = survival_curve(df["t_end"].to_numpy(), observed_from_outcome(df["outcome"]))
        if a.labels and i < len(a.labels):
            label = a.labels[i]
        else:
            sc = json.loads((Path(run) / "scene.json").read_text())["scene"]
            label = f"E0={sc['energy']}, γ={sc['gamma']} (N={len(df)})"
        curves.append({"t": t, "P": P, "P_err": err, "label": label})
    plot_survival(curves, a.png, title="Survival probability")
    print(f"wrote {a.png}")
    return 0


def cmd_study(a):
    from .studies import run_stage

    run_stage(a.name, a.stage, a.scale, workers=a.workers, progress=not a.quiet)
    return 0


def main(argv=None):
    from .runner import RunError
    from .scene import SceneError

    a = build_parser().parse_args(argv)
    try:
        return {"simulate": cmd_simulate, "survival": cmd_survival, "study": cmd_study}[a.command](a)
    except SceneError as exc:
        print(f"hhscatter: error: {exc}", file=sys.stderr)
        return 2
    except RunError as exc:
        print(f"hhscatter: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("hhscatter: interrupted; rerun with --resume to continue", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
