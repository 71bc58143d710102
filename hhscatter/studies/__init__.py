"""Studies: one per figure of the reference paper (and the checks beyond it).

A study is one folder ``studies/<name>/`` (adding a study is making a folder):

``study.toml``  its parameters, the one place they live, with ``[about]`` (what it
                is) and ``[needs]`` (the studies whose published outputs it reads:
                the one declared dependency graph, :mod:`hhscatter.studies.graph`);
``study.py``    its three stages (loaded from the folder by path, :func:`stage_module`);
``figure.py``   its figure code; ``page.md`` its page of the docs;
``out/<scale>/`` what it makes.

The stages make runs as separate targets:

``simulate(study, workers)``
    integrates the study's scenes into immutable raw run directories
    ``studies/<name>/out/<scale>/raw/<key>/`` (Parquet, see :mod:`hhscatter.data.schema`);
``analyze(study)``
    turns raw tables into derived tables under ``.../derived/`` and the study's
    numbers ``.../<name>.json`` with the pure functions of :mod:`hhscatter.analysis`;
    other studies' outputs are read only as published (their JSON and derived
    tables, :mod:`hhscatter.studies._upstream`), never their raw runs or code;
``plot(study)``
    draws ``.../<name>.png`` from the derived tables only (it computes nothing).

``study.toml`` layout::

    convention = "paper" # optional: scene keys shared by several studies, declared once in
                         # studies/conventions.toml (a study cannot set them again)
    [about]              # title, paper figure, summary (make help, docs nav, report)
    [needs]              # role = upstream study (hhscatter.studies.graph: the one dependency graph)
    [scene]              # base Scene fields shared by the study's scenes
    [sections]           # optional SectionWindow fields
    [study]              # study parameters (energy grids, windows, ...)
    [scale.paper.scene]  # overrides per scale; 'quick' is the default scale,
    [scale.paper.study]  # 'tiny' the scale of the end-to-end tests

The numbers JSON follows one convention so the report can tabulate it: a value
with an uncertainty is a :class:`~hhscatter.analysis.stats.measured.Measured`, written ``{"value": v, "err": e}``,
and the list
``"paper_comparison"`` holds rows ``{quantity, ours, err, paper, verdict, note}``.
"""

from __future__ import annotations

import json
from pathlib import Path

from hhscatter.analysis.stats.library_warnings import reset_warning_counts, warning_counts
from hhscatter.data.verify import run_status
from hhscatter.errors import StudyError
from hhscatter.studies._upstream import UpstreamError, dev_fallback_enabled
from hhscatter.studies.cost import meter, record
from hhscatter.studies.jsonio import write_json_atomic
from hhscatter.studies.study import (
    DEFAULT_SCALE,
    SCENE_TABLES,
    STAGES,
    Study,
    conventions_path,
    load_conventions,
    load_study,
    missing_upstream,
    simulate_inputs,
    stage_module,
    studies_root,
    study_names,
)

__all__ = [
    "DEFAULT_SCALE",
    "SCENE_TABLES",
    "STAGES",
    "Study",
    "checked_raw_runs",
    "conventions_path",
    "load_conventions",
    "load_study",
    "missing_upstream",
    "run_stage",
    "simulate_inputs",
    "stage_module",
    "studies_root",
    "study_names",
    "write_json_atomic",
]


def run_stage(
    name: str, stage: str, scale: str = DEFAULT_SCALE, *, workers=None, progress=True, root: Path | None = None
):
    """Run one stage of a study (simulate, analyze, plot, or all three) at a scale, recording its cost."""
    if stage not in (*STAGES, "all"):
        raise StudyError(f"stage must be one of {[*STAGES, 'all']}, got {stage!r}")
    study = load_study(name, scale, root=root)
    mod = stage_module(name, root)
    stages = STAGES if stage == "all" else (stage,)
    for st in stages:
        study.comparisons = []
        study.orbits_run, study.chunks_resumed = 0, 0
        try:
            with meter(st, workers) as cost:
                _run_one(study, mod, st, name, scale, workers, progress)
                cost.completed = True
        finally:  # an interrupted stage is recorded too: its resumed continuation adds to it
            cost.orbits, cost.chunks_resumed = study.orbits_run, study.chunks_resumed
            if study.out.is_dir():
                record(study.out, cost)


def checked_raw_runs(study) -> dict:
    """The raw runs analyze may read, {key: {scene_hash, orbits, complete}}, each checked.

    StudyError (exit 2, before any analysis) if the simulate stage did not finish for the current
    study.toml (``raw/done.json`` missing, or made from another configuration), or if a raw run it made
    is incomplete or now holds another scene. A study without raw runs (one that reads only upstream
    outputs) passes.
    """
    raw = study.out / "raw"
    done = raw / "done.json"
    again = f"run `hhscatter study {study.name} simulate --scale {study.scale}` first"
    if not done.exists():
        if raw.is_dir() and any((p / "scene.json").exists() for p in raw.iterdir() if p.is_dir()):
            raise StudyError(f"{study.name} analyze: the simulate stage has not finished ({done} is missing); {again}")
        return {}
    rec = json.loads(done.read_text())
    was = rec.get("inputs") or {}
    now = simulate_inputs(study, (was.get("study") or {}).keys())
    changed = [f"[{t}]" for t in SCENE_TABLES if (was.get("tables") or {}).get(t) != now["tables"][t]]
    changed += [
        f"[study] {k} ({v!r} → {now['study'][k]!r})"
        for k, v in (was.get("study") or {}).items()
        if v != now["study"][k]
    ]
    if "inputs" not in rec or changed:
        raise StudyError(
            f"{study.name} analyze: the raw runs in {raw} were made from another study.toml "
            f"({', '.join(changed) or 'no record of its inputs'} changed since simulate); {again}"
        )
    runs = {}
    for key, want in rec.get("runs", {}).items():
        st = run_status(raw / key)
        if st["scene_hash"] != want["scene_hash"]:
            raise StudyError(
                f"{study.name} analyze: raw run {raw / key} holds another scene than simulate made "
                f"(hash {str(st['scene_hash'])[:12]}…, expected {want['scene_hash'][:12]}…); {again}"
            )
        if not st["complete"]:
            raise StudyError(
                f"{study.name} analyze: raw run {raw / key} is incomplete ({st['chunks_done']} of "
                f"{st['chunks']} chunks finished); {again}"
            )
        runs[key] = {"scene_hash": want["scene_hash"], "orbits": st["orbits"], "complete": True}
    return runs


def _run_one(study, mod, st, name, scale, workers, progress):
    if st == "simulate":
        done = study.out / "raw" / "done.json"
        done.unlink(missing_ok=True)  # the record of a finished simulate stage: invalid until this one ends
        study.raw_runs, study.params_read = {}, set()
        try:
            mod.simulate(study, workers=workers, progress=progress)
        finally:
            read, study.params_read = study.params_read, None
        write_json_atomic(
            done, {"study": name, "scale": scale, "inputs": simulate_inputs(study, read), "runs": study.raw_runs}
        )
        print(f"{name} simulate: raw runs in {study.out / 'raw'}", flush=True)
    elif st == "analyze":
        missing = [] if dev_fallback_enabled() else missing_upstream(study)
        if missing:
            raise UpstreamError(
                f"{name} needs the published outputs of {', '.join(missing)} (declared in [needs] of "
                f"{study.root / 'study.toml'}); run `make {name} SCALE={scale}`, which builds them first"
            )
        study.raw_runs = checked_raw_runs(study)
        reset_warning_counts()  # the numbers JSON records the library warnings of this analysis alone
        mod.analyze(study)
        derived = study.out / "derived"
        extra = f" and {len(list(derived.iterdir()))} derived table(s) in {derived}" if derived.is_dir() else ""
        print(f"{name} analyze: wrote {study.numbers_path}{extra}", flush=True)
        counts = warning_counts()
        if counts:
            total = sum(r["count"] for r in counts)
            print(
                f"{name} analyze: {total} library warning(s) counted, not shown, in {len(counts)} kind(s) "
                f"(key library_warnings of {study.numbers_path.name})",
                flush=True,
            )
    else:
        import matplotlib  # deferred: matplotlib loads on first use

        matplotlib.use("Agg")
        if not study.numbers_path.exists():
            raise StudyError(
                f"{name} plot: {study.numbers_path} is missing; run `hhscatter study {name} analyze "
                f"--scale {scale}` first"
            )
        # the numbers drawn are the ones analyze wrote for this study.toml and these upstream numbers
        study.verify_numbers(upstream=not dev_fallback_enabled())
        mod.plot(study)
        print(f"{name} plot: wrote {study.figure_path}", flush=True)
