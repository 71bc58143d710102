"""Command line: ``hhscatter simulate``, ``hhscatter survival`` and ``hhscatter study``.

Exit status: 0 on success, 2 on bad input (the message names the parameter and
its allowed range; nothing has been computed; no traceback), 1 on other
failures, 130 when interrupted by SIGINT (Ctrl-C) and 143 by SIGTERM: one line
says what was kept and how to continue, without a traceback.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import re
import signal
import sys
from pathlib import Path

from hhscatter.errors import ConfigError, HHScatterError

re_unrecognized = re.compile(r"unrecognized arguments: (.*)")
re_choice = re.compile(r"invalid choice: '([^']*)' \(choose from (.*)\)")

DESCRIPTION = (
    "Exact-event ensemble simulations of (dissipative) chaotic scattering in the Hénon–Heiles potential: "
    "integrate ensembles into Parquet tables (simulate), plot their survival probability (survival), and "
    "run the paper's studies (study)."
)
EPILOG = """examples:
  hhscatter simulate --energy 0.27 -n 1e5 --out runs/e027
  hhscatter simulate --energy 0.25,0.3 --gamma 0,0.01 -n 1e4 --out runs/grid
  hhscatter simulate --out runs/grid --resume        # continue a killed run (scene from runs/grid/scene.json)
  hhscatter survival runs/grid --png grid.png        # one P(t) per grid point
  hhscatter study fig2 all --scale quick

'hhscatter COMMAND --help' lists a command's options."""


class UsageError(HHScatterError):
    """Bad command-line input found after parsing (exit status 2, no traceback)."""


class _Parser(argparse.ArgumentParser):
    """argparse with "did you mean" for a mistyped flag, subcommand or choice (Python < 3.14 has none)."""

    def _all_options(self):
        opts = set(self._option_string_actions)
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub in action.choices.values():
                    opts |= set(sub._option_string_actions)
        return opts

    def error(self, message):
        from hhscatter.scene.schema import (
            did_you_mean,  # deferred: `hhscatter --help` starts without the engine and tables
        )

        m = re_unrecognized.match(message)
        if m:
            hints = [
                did_you_mean(a.split("=", 1)[0], self._all_options()) for a in m.group(1).split() if a.startswith("-")
            ]
            message += "".join(h.replace(" (", "; ", 1).rstrip(")") for h in hints if h)
        m = re_choice.search(message)
        if m:
            hint = did_you_mean(m.group(1), re.findall(r"'([^']+)'", m.group(2)))
            message += hint.replace(" (", "; ", 1).rstrip(")") if hint else ""
        super().error(message)


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
    """An integer, also written as a float with an integral value (1e5, 2.0e4); 1.5 or nan are refused."""
    try:
        return int(s)
    except ValueError:
        pass
    try:
        v = float(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {s!r}") from None
    if not math.isfinite(v) or v != int(v):
        raise argparse.ArgumentTypeError(f"not an integer: {s!r} (a count must be a whole number)")
    return int(v)


def _snapshots(s):
    """'START:STOP:STEP' (both ends included) or a comma-separated list of times."""
    if ":" in s:
        parts = s.split(":")
        if len(parts) != 3:
            raise argparse.ArgumentTypeError(f"snapshots: expected START:STOP:STEP, got {s!r}")
        return dict(zip(("start", "stop", "step"), (_float(x) for x in parts)))
    v = _floats(s)
    return {"times": v if isinstance(v, list) else [v]}


class _SystemOption(argparse.Action):
    """``--system NAME|EXPR``: stores the value; its help names the built-ins of the registry
    (:data:`hhscatter.model.builtins.BUILTINS`), read only when the help is shown."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)

    @property
    def help(self) -> str:
        from hhscatter.model.builtins import BUILTINS  # deferred: `hhscatter --help` starts without sympy

        return (
            f"a built-in ({', '.join(BUILTINS)}) "
            "or a potential V in x, y and parameters, e.g. '0.5*(x**2 + y**2) - eps*x**2*y**2'"
        )

    @help.setter
    def help(self, value) -> None:  # argparse sets it; the text above is the one shown
        pass


def _system_flags(s) -> None:
    """--system, --param, --dissipation of ``simulate`` (hhscatter.model.spec)."""
    sy = s.add_argument_group(
        "system",
        "the system as data (default Hénon–Heiles, ω = λ = 1, linear drag); they override the scene file's [system]",
    )
    sy.add_argument(
        "--system",
        metavar="NAME|EXPR",
        action=_SystemOption,
    )
    sy.add_argument(
        "--param",
        action="append",
        type=_param,
        metavar="NAME=VALUE",
        default=[],
        help="a parameter of the system (repeatable), e.g. --param eps=0.25",
    )
    sy.add_argument("--dissipation", choices=["linear", "quadratic"], help="drag law: −γp (linear, default) or −γ|p|p")


def build_parser():
    from hhscatter import __version__  # deferred: `hhscatter --help` starts without the engine and tables

    p = _Parser(
        prog="hhscatter", description=DESCRIPTION, epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--version", action="version", version=f"hhscatter {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    s = sub.add_parser(
        "simulate",
        help="integrate an ensemble and write Parquet tables",
        description="Integrate an ensemble of orbits of a system (Hénon–Heiles by default; exact event times) and write "
        "the lifetimes (and, if asked, sections/snapshots) tables as Parquet datasets.",
    )
    s.add_argument(
        "scene",
        nargs="?",
        help="scene TOML file (flags below override its values); with --resume and "
        "no scene file, the scene is read from OUT/scene.json",
    )
    s.add_argument("--scale", help="named scale in the scene file, e.g. 'paper' (default: quick)")
    s.add_argument(
        "--energy",
        type=_floats,
        help="initial energy E0 (> the system's E_c: 1/6 for Hénon–Heiles with ω=λ=1); a list 0.25,0.3 "
        "makes a grid run",
    )
    s.add_argument("--gamma", type=_floats, help="drag γ ≥ 0 (0 = conservative); a list 0,0.01 makes a grid run")
    s.add_argument("-n", type=_int, help="number of orbits N > 0 (per grid point); 1e5 is accepted")
    s.add_argument("--seed", type=_int, help="seed ≥ 0 (with the orbit index it fixes every orbit)")
    s.add_argument(
        "--region",
        choices=["disk", "well", "square"],
        help="initial-condition region: disk (r < radius), well (the well's part of V < E_c: the saddle "
        "triangle of Hénon–Heiles), square (the authors' [-r_s, r_s]² with V < E; orbits starting at "
        "r ≥ r_esc are escaped at t = 0)",
    )
    s.add_argument(
        "--radius",
        type=_float,
        help="disk radius (default: half the system's saddle distance r_s; 0.5 for Hénon–Heiles)",
    )
    s.add_argument(
        "--r-esc",
        type=_float,
        dest="r_esc",
        help="escape radius (default: the system's; 1.5 for Hénon–Heiles, the paper used 1.03, see study resc)",
    )
    _system_flags(s)
    s.add_argument("--t-max", type=_float, dest="t_max", help="maximum orbit time (default 5000)")
    s.add_argument("--tol", type=_float, help="integrator tolerance in [1e-18, 1e-6] (default 1e-15)")
    s.add_argument("--chunk-size", type=_int, dest="chunk_size", help="orbits per part file (default 10000)")
    s.add_argument("--batch-size", type=_int, dest="batch_size", help="SIMD lanes (default: heyoka's choice)")
    sec = s.add_argument_group(
        "sections",
        "record crossings of the section ṙ = 0, φ̇ > 0 (any of these flags "
        "turns it on; they override the scene file's [sections])",
    )
    sec.add_argument("--sections", action="store_true", help="record every crossing (t > 0)")
    sec.add_argument(
        "--sections-t-from", type=_float, dest="sections_t_from", metavar="T", help="only crossings at orbit time ≥ T"
    )
    sec.add_argument(
        "--sections-t-to", type=_float, dest="sections_t_to", metavar="T", help="only crossings at orbit time ≤ T"
    )
    sec.add_argument(
        "--sections-e-min", type=_float, dest="sections_e_min", metavar="E", help="only crossings with energy ≥ E"
    )
    sec.add_argument(
        "--sections-e-max", type=_float, dest="sections_e_max", metavar="E", help="only crossings with energy ≤ E"
    )
    sec.add_argument(
        "--sections-first-only",
        action="store_true",
        dest="sections_first_only",
        help="only the first crossing in the window per orbit",
    )
    s.add_argument(
        "--snapshots",
        type=_snapshots,
        metavar="START:STOP:STEP|T1,T2,…",
        help="record the energy of every live orbit at these orbit times (overrides [snapshots])",
    )
    s.add_argument("--ics", help="Parquet/CSV table of initial states with columns x, y, px, py [, traj_id]")
    s.add_argument(
        "--out",
        required=True,
        help="output directory (named explicitly: '.' for the working directory), or "
        "a URL pyarrow/fsspec can write (s3://…)",
    )
    s.add_argument(
        "--workers",
        type=_int,
        help="worker processes (default: all cores; more than the cores this process may use runs that many)",
    )
    s.add_argument(
        "--scheduler",
        help="run the chunks on Dask: 'local' (a LocalCluster of --workers processes) "
        "or a scheduler address tcp://HOST:PORT (needs the 'dask' extra)",
    )
    g = s.add_mutually_exclusive_group()
    g.add_argument("--overwrite", action="store_true", help="replace the tables in a non-empty --out")
    g.add_argument("--resume", action="store_true", help="keep verified finished chunks in --out, redo the rest")
    _progress_flags(s)

    v = sub.add_parser(
        "survival",
        help="plot P(t) of one or more runs to a PNG (one curve per grid point)",
        description="Plot the Kaplan–Meier survival probability P(t) of one or more runs; a grid "
        "run gives one curve per (E0, γ) point.",
    )
    v.add_argument("runs", nargs="+", help="run directories (outputs of simulate)")
    v.add_argument("--png", required=True, help="output PNG path, ending in .png (its folder must exist)")
    v.add_argument("--labels", nargs="*", help="curve labels, one per curve in order (default: E0, γ and N)")

    st = sub.add_parser(
        "study",
        help="run one stage of a study (simulate → analyze → plot)",
        description="Run a stage of a study in studies/<name>/: 'simulate' writes raw Parquet runs, "
        "'analyze' derived tables and <name>.json, 'plot' <name>.png; 'all' runs the three. The studies folder is "
        "studies/ of the repository the command runs in (the working directory or a parent), or --studies.",
        epilog=_studies_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    st.add_argument("name", help="study name (a folder of studies/ with a study.toml), e.g. fig2; listed below")
    st.add_argument("stage", choices=["simulate", "analyze", "plot", "all"])
    st.add_argument("--scale", default="quick", help="'quick' (default), 'paper', or another scale in study.toml")
    st.add_argument(
        "--workers",
        type=_int,
        help="worker processes (default: all cores; more than the cores this process may use runs that many)",
    )
    st.add_argument(
        "--studies",
        metavar="DIR",
        help="the studies folder (default: $HHSCATTER_STUDIES, else studies/ of the repository the command runs in)",
    )
    _progress_flags(st)
    return p


def _study_graph():
    """hhscatter/studies/graph.py loaded by path: it is stdlib only, and listing the studies in every command's help
    must not load the study framework (the package hhscatter.studies imports the runner, the tables and pydantic:
    ≈ 0.25 s of start-up for every ``hhscatter`` call). The Makefile and docs/gen_studies.py load it the same way."""
    name = "hhscatter_cli_study_graph"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, Path(__file__).resolve().parent / "studies" / "graph.py")
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod  # (dataclasses look their module up while the file executes)
        spec.loader.exec_module(mod)
    return sys.modules[name]


def _studies_epilog() -> str:
    """The studies, one line each (name, title, summary), from the study folders; empty if there are none."""
    try:
        infos = _study_graph().studies()
    except Exception:  # noqa: BLE001 - --help must work even if a study.toml is broken
        return ""
    if not infos:
        return ""
    width = max(len(s.name) for s in infos)
    lines = [f"  {s.name:<{width}}  {s.title}" + (f" — {s.summary}" if s.summary else "") for s in infos]
    return "studies:\n" + "\n".join(lines)


def _progress_flags(parser):
    g = parser.add_mutually_exclusive_group()
    g.add_argument(
        "--progress",
        action="store_true",
        help="show progress even when stderr is not a terminal (then as plain lines, no carriage returns)",
    )
    g.add_argument(
        "--no-progress",
        "--quiet",
        action="store_true",
        dest="quiet",
        help="no progress (default when stderr is not a terminal)",
    )


def _progress(a):
    """True (a bar) on a terminal, 'plain' lines in logs with --progress, else False."""
    if a.quiet:
        return False
    if sys.stderr.isatty():
        return True
    return "plain" if a.progress else False


def _resumed_scene(out):
    """The scene dict of OUT/scene.json (what --resume without a scene file continues), or None."""
    import json  # deferred: `hhscatter --help` starts without the engine and tables

    from hhscatter.data.store import Store  # deferred: `hhscatter --help` starts without the engine and tables

    try:
        store = Store(out)
        if not store.exists("scene.json"):
            return None
        return json.loads(store.read_text("scene.json"))["scene"]
    except (ValueError, KeyError, OSError) as exc:
        raise UsageError(f"--resume: cannot read the scene of {out}/scene.json ({exc})") from None


def _scene_from_args(a):
    """The Scene (or, when --energy/--gamma or the file give lists, the Grid) of the simulate flags."""
    from hhscatter.scene.grid import run_from_dict  # deferred: `hhscatter --help` starts without the engine and tables
    from hhscatter.scene.schema import (
        scene_dict_from_toml,  # deferred: `hhscatter --help` starts without the engine and tables
    )

    if a.ics is not None:
        given = [f"--{k}" for k in ("region", "radius") if getattr(a, k) is not None]
        if given:
            raise UsageError(
                f"{' and '.join(given)} {'is' if len(given) == 1 else 'are'} for initial conditions "
                "sampled in a region; with --ics the table gives every initial state: drop "
                f"{' and '.join(given)}"
            )
    flags = {
        k: getattr(a, k)
        for k in (
            "energy",
            "gamma",
            "n",
            "seed",
            "region",
            "radius",
            "r_esc",
            "t_max",
            "tol",
            "chunk_size",
            "batch_size",
        )
    }
    for k, v in flags.items():
        for x in v if isinstance(v, list) else [v]:
            if isinstance(x, float) and not math.isfinite(x):
                raise ConfigError(f"{k.replace('_', '-')} must be finite, got {x}")
    if a.ics:
        from hhscatter.scene.ics import read_ics_table  # deferred: `hhscatter --help` starts without numpy and pydantic

        states, _ = read_ics_table(a.ics)
        if flags["n"] is not None and flags["n"] != len(states):
            raise ConfigError(f"n = {flags['n']} but the ics table has {len(states)} rows")
        flags["n"] = len(states)
        flags["ics"] = str(Path(a.ics).resolve())
    if a.scene:
        d = scene_dict_from_toml(a.scene, a.scale)
        if a.ics is not None or d.get("ics") is not None:
            given = [k for k in ("region", "radius") if k in d]
            if given:
                raise ConfigError(
                    f"{a.scene}: [scene] {', '.join(given)} with ics: the IC table gives every initial "
                    f"state, {' and '.join(given)} would be ignored; remove {' and '.join(given)}"
                )
    elif a.scale:
        raise ConfigError("--scale needs a scene file")
    elif a.resume and (old := _resumed_scene(a.out)) is not None:
        d = old  # flags given as well still override it (a different scene is then refused by the hash check)
    else:
        d = {"name": Path(a.out).name}
        if flags["n"] is None:
            hint = " (--resume found no scene.json in --out)" if a.resume else ""
            raise ConfigError(f"n (number of orbits) is required: give -n or a scene file{hint}")
        if flags["energy"] is None and not a.ics:
            raise ConfigError("energy is required: give --energy or a scene file")
    d.update({k: v for k, v in flags.items() if v is not None})
    window = {k: getattr(a, f"sections_{k}") for k in ("t_from", "t_to", "e_min", "e_max")}
    window = {k: v for k, v in window.items() if v is not None}
    if a.sections_first_only:
        window["first_only"] = True
    if window or a.sections:
        d["sections"] = {**(d.get("sections") or {}), **window}
    if a.snapshots is not None:
        d["snapshots"] = a.snapshots
    if a.system is not None or a.param or a.dissipation:
        d["system"] = _system_from_args(a, d.get("system"))
    return run_from_dict(d)


def _system_from_args(a, base: dict | None) -> dict:
    """The [system] spec of --system/--param/--dissipation over the scene file's (hhscatter.model.spec)."""
    spec = dict(base or {})
    if a.system is not None:
        is_name = re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", a.system) and a.system not in ("x", "y")
        spec.pop("name", None)
        spec.pop("potential", None)
        spec["name" if is_name else "potential"] = a.system
    if a.param:
        names = [k for k, _ in a.param]
        twice = sorted({k for k in names if names.count(k) > 1})
        if twice:
            values = {k: [v for n, v in a.param if n == k] for k in twice}
            raise UsageError(
                "--param "
                + "; ".join(f"{k} given {len(v)} times ({', '.join(f'{x:g}' for x in v)})" for k, v in values.items())
                + ": give each parameter once"
            )
        spec["params"] = {**(spec.get("params") or {}), **dict(a.param)}
    if a.dissipation:
        spec["dissipation"] = a.dissipation
    if "name" not in spec and "potential" not in spec:
        spec["name"] = "henon_heiles"
    return spec


def _param(s: str) -> tuple[str, float]:
    name, eq, value = s.partition("=")
    if not eq or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name.strip()):
        raise argparse.ArgumentTypeError(f"param: expected NAME=VALUE, got {s!r}")
    return name.strip(), _float(value)


def cmd_simulate(a):
    from hhscatter.data.store import Store  # deferred: `hhscatter --help` starts without the engine and tables
    from hhscatter.data.verify import describe_run  # deferred: `hhscatter --help` starts without the engine and tables
    from hhscatter.run.runner import simulate  # deferred: `hhscatter --help` starts without the engine and tables

    scene = _scene_from_args(a)
    if a.scheduler is None or a.scheduler == "local":
        _note_workers(a.workers)
    summary = simulate(
        scene,
        a.out,
        workers=a.workers,
        overwrite=a.overwrite,
        resume=a.resume,
        progress=_progress(a),
        scheduler=a.scheduler,
    )
    print(summary.line())
    store = Store(a.out)
    print(run_report(store.root if store.local else store.url, describe_run(a.out)))
    return 0


def _note_workers(workers) -> None:
    """One line on stderr when --workers asks for more processes than the CPUs this process may use: that many
    run (more would only compete for them, each with its own compiled integrator)."""
    from hhscatter.run.worker import default_workers  # deferred: `hhscatter --help` starts without the engine

    cpus = default_workers()
    if workers is not None and workers > cpus:
        print(
            f"hhscatter: --workers {workers} is more than the {cpus} CPU(s) this process may use: "
            f"{cpus} worker process(es) run",
            file=sys.stderr,
        )


def run_report(out, info: dict) -> str:
    """The closing lines of ``simulate``: where the tables are, their row counts, outcomes per grid point."""
    rows = ", ".join(f"{name} {n} rows" for name, n in info["rows"].items())
    lines = [f"wrote {out}: {rows}"]
    for p in info["points"]:
        e = "E0 from the IC table" if p["energy"] is None else f"E0={p['energy']:g}"
        lines.append(
            f"  {e}, γ={p['gamma']:g}: escaped {p['escaped']}, settled {p['settled']}, "
            f"censored {p['censored']}" + (f", stopped {p['stopped']}" if p.get("stopped") else "")
        )
    return "\n".join(lines)


def cmd_survival(a):
    # no pyplot: no backend is chosen or changed
    from matplotlib.figure import Figure  # deferred: `hhscatter --help` starts without the engine and tables

    from hhscatter.api import (  # deferred: `hhscatter --help` starts without the engine and tables
        plot_survival,
        survival,
    )
    from hhscatter.data.read import read_lifetimes  # deferred: `hhscatter --help` starts without the engine and tables

    png = Path(a.png)
    if png.suffix.lower() != ".png":
        raise UsageError(f"--png must name a .png file, got {a.png!r}")
    if not png.parent.is_dir():
        raise UsageError(f"--png: folder {png.parent} does not exist")
    curves = []
    for run in a.runs:
        if not Path(run).is_dir() and "://" not in run:
            raise UsageError(f"run {run!r} does not exist (give a directory written by hhscatter simulate)")
        try:  # the run checked as every reader checks it, on one small column; then read as survival needs it
            read_lifetimes(run, columns=["outcome"], categorical=True)
        except FileNotFoundError as exc:
            raise UsageError(f"run {run!r}: {exc}") from None
        curves.append(survival(run))  # part by part, only the columns P(t) needs
    n_curves = sum(len(c) for c in curves)
    if a.labels and len(a.labels) != n_curves:
        raise UsageError(
            f"--labels: {len(a.labels)} label(s) for {n_curves} curve(s) "
            f"({', '.join(f'{r}: {len(c)}' for r, c in zip(a.runs, curves))})"
        )
    fig = Figure(figsize=(6, 4.2), constrained_layout=True)
    ax = plot_survival(curves, ax=fig.subplots(), labels=a.labels or None)
    ax.set_title("Survival probability")
    ax.grid(True, which="both", alpha=0.3)
    fig.savefig(png, dpi=150)
    print(f"wrote {png} ({n_curves} curve{'s' if n_curves != 1 else ''})")
    return 0


def cmd_study(a):
    from hhscatter.studies import run_stage  # deferred: `hhscatter --help` starts without the engine and tables

    _note_workers(a.workers)
    run_stage(
        a.name, a.stage, a.scale, workers=a.workers, progress=_progress(a), root=Path(a.studies) if a.studies else None
    )
    return 0


#: the text options of each command (argparse names): an empty or blank value is refused, never read as "not given"
TEXT_OPTIONS = {
    "simulate": ("scene", "scale", "system", "ics", "out", "scheduler"),
    "survival": ("runs", "png", "labels"),
    "study": ("name", "scale"),
}


def _check_text(a) -> None:
    """UsageError for an empty or blank text option: ``--system ""`` (an unset shell variable) must not mean the
    default system, nor ``--out ""`` the working directory."""
    for key in TEXT_OPTIONS.get(a.command, ()):
        value = getattr(a, key, None)
        for v in value if isinstance(value, list) else [value]:
            if v is not None and not v.strip():
                flag = key if key in ("scene", "runs", "name") else f"--{key.replace('_', '-')}"
                raise UsageError(
                    f"{flag} must not be empty, got {v!r}"
                    + (" (name the working directory as '.')" if key == "out" else "")
                )


#: the exit status of a command ended by a signal: 128 + the signal's number (the shells' convention)
SIGNAL_EXIT = {signal.SIGINT: 130, signal.SIGTERM: 143}


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM arrived: raised where the command is, so that its cleanup runs (a run's lock is
    released, a run that wrote no chunk is removed) before the command ends with one line and 128 + the signal."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


_received: list[int] = []  # the signals received by this command, in order


def _on_signal(signum, frame):
    runner = sys.modules.get("hhscatter.run.runner")
    if runner is not None and runner.defer_signal(signum):  # a worker process is being started: raised at its end
        return
    _received.append(signum)
    if runner is not None:  # the run stops after its chunk even if the exception below is lost on its way
        runner.request_stop(signum)
    if len(_received) == 1:  # once: a second Ctrl-C must not break the cleanup of the first
        raise Interrupted(signum)
    if len(_received) >= 3:  # a third: the cleanup is not wanted, end now
        os._exit(SIGNAL_EXIT.get(signum, 128 + int(signum)))


def _catch_signals() -> dict:
    """SIGINT and SIGTERM raise :class:`Interrupted` in the main thread (a no-op elsewhere); returns the handlers
    they had, for :func:`_restore_signals`."""
    _received.clear()
    runner = sys.modules.get("hhscatter.run.runner")
    if runner is not None:
        runner.clear_stop()
    before = {}
    try:
        for sig in SIGNAL_EXIT:
            before[sig] = signal.signal(sig, _on_signal)
    except ValueError:  # not the main thread: signals stay as they are
        pass
    return before


def _restore_signals(before: dict) -> None:
    for sig, handler in before.items():
        signal.signal(sig, handler if handler is not None else signal.SIG_DFL)


def _interrupted_advice(a) -> str:
    """What an interrupted command kept and how to continue it: one clause for the closing line."""
    if a is None:
        return "nothing was done"
    if a.command == "simulate":
        from hhscatter.data.store import Store  # deferred: `hhscatter --help` starts without the engine and tables

        try:
            kept = Store(a.out).exists("scene.json")
        except (OSError, ValueError):
            kept = False
        if kept:
            return f"the finished chunks in {a.out} are kept: run the command again with --resume to continue"
        return f"no chunk had finished and nothing is left in {a.out}: run the command again"
    if a.command == "study":
        again = f"hhscatter study {a.name} {a.stage} --scale {a.scale}"
        if a.stage in ("simulate", "all"):
            return f"finished runs and chunks are kept: run `{again}` again to continue"
        return f"the {a.stage} stage did not finish and replaced none of its outputs: run `{again}` again"
    return "nothing was written"


def main(argv=None):
    before = _catch_signals()
    try:
        return _main(argv)
    finally:
        _restore_signals(before)


def _main(argv):
    a = None
    try:
        a = build_parser().parse_args(argv)
        _check_text(a)
        rc = {"simulate": cmd_simulate, "survival": cmd_survival, "study": cmd_study}[a.command](a)
        if _received:  # the signal's exception was lost on its way (a finaliser, a callback): it is still the news
            return _interrupted(a)
        return rc
    except HHScatterError as exc:  # bad input (2, before any work), or a run that could not complete (1)
        if _received:
            return _interrupted(a)
        print(f"hhscatter: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except FileNotFoundError as exc:  # a run or file that is not there
        if _received:
            return _interrupted(a)
        print(f"hhscatter: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `hhscatter … | head -1`: the reader left; the run itself is complete
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at exit
        return 141
    except KeyboardInterrupt:
        if not _received:
            _received.append(signal.SIGINT)
        return _interrupted(a)
    except BaseException:
        if _received:  # whatever the signal broke on its way out (a half-made import, a pool): the signal is the news
            return _interrupted(a)
        raise


def _interrupted(a) -> int:
    """Print the one closing line of an interrupted command; its exit status (130 SIGINT, 143 SIGTERM)."""
    signum = _received[0]
    try:
        advice = _interrupted_advice(a)
    except Exception:  # noqa: BLE001 - the closing line must come out whatever the state
        advice = "see the output folder"
    print(f"hhscatter: interrupted by {signal.Signals(signum).name}; {advice}", file=sys.stderr)
    return SIGNAL_EXIT.get(signum, 128 + int(signum))


if __name__ == "__main__":
    sys.exit(main())
