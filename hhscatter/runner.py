"""Run a scene: chunk planning, worker processes, part files, resume, progress.

``simulate(scene, out, workers=None, overwrite=False, resume=False)`` checks
everything it can before any work (output directory writable and empty or
explicitly overwritten/resumed, initial conditions valid), then integrates
the chunks on a process pool and writes one part file per chunk and table.
"""
from __future__ import annotations

import json
import os
import shutil
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .scene import Scene, SceneError, scene_from_dict
from .tables import TABLES, part_name, read_meta

SCENE_FILE = "scene.json"


@dataclass
class RunSummary:
    """Counts per outcome and timings of a run (or of one chunk)."""

    n: int = 0
    escaped: int = 0
    settled: int = 0
    censored: int = 0
    n_sections: int = 0
    n_snapshots: int = 0
    compute_seconds: float = 0.0  # time spent in chunks, summed over workers
    wall_seconds: float = 0.0
    chunks_done: int = 0
    chunks_skipped: int = 0
    workers: int = 1

    def add(self, other: "RunSummary"):
        for k in ("n", "escaped", "settled", "censored", "n_sections", "n_snapshots", "compute_seconds"):
            setattr(self, k, getattr(self, k) + getattr(other, k))
        self.chunks_done += 1

    def line(self) -> str:
        us = 1e6 * self.wall_seconds / max(self.n, 1)
        us_core = 1e6 * self.compute_seconds / max(self.n, 1)
        skipped = f", {self.chunks_skipped} chunk(s) resumed" if self.chunks_skipped else ""
        return (
            f"{self.n} orbits: escaped {self.escaped}, settled {self.settled}, censored {self.censored}"
            f" | wall {self.wall_seconds:.2f} s, {us:.2f} µs/orbit, {us_core:.2f} µs/orbit/core"
            f" ({self.workers} worker{'s' if self.workers != 1 else ''}{skipped})"
        )


def plan_chunks(scene: Scene):
    """plan_chunks(scene) -> [(chunk, start, stop)] covering orbits 0..n−1."""
    c = scene.chunk_size
    return [(i, s, min(s + c, scene.n)) for i, s in enumerate(range(0, scene.n, c))]


def tables_of(scene: Scene):
    names = ["lifetimes"]
    if scene.sections is not None:
        names.append("sections")
    if scene.snapshots:
        names.append("snapshots")
    return names


def _chunk_ics(scene, start, stop, table_ics):
    if table_ics is not None:
        states, ids = table_ics
        return states[start:stop], ids[start:stop]
    from .ics import region_ics

    return region_ics(scene, start, stop), np.arange(start, stop, dtype=np.int64)


def run_one_chunk(scene_json: str, chunk: int, start: int, stop: int, out: str, ics=None, ids=None):
    """Worker entry: integrate one chunk, write its part files, return a RunSummary."""
    from .engine import run_chunk
    from .tables import provenance, to_arrow, write_part

    scene = scene_from_dict(_decode(json.loads(scene_json)))
    if ics is None:
        ics, ids = _chunk_ics(scene, start, stop, None)
    t0 = time.perf_counter()
    res = run_chunk(scene, ics, ids)
    elapsed = time.perf_counter() - t0
    meta = {
        "scene": json.loads(scene_json),
        "scene_hash": scene.result_hash(),
        "chunk": chunk,
        "orbits": [start, stop],
        **provenance(),
    }
    rows = {"lifetimes": res.lifetimes, "sections": res.sections, "snapshots": res.snapshots}
    # lifetimes last: its presence marks a complete chunk
    for name in reversed(tables_of(scene)):
        table = to_arrow(name, rows[name])
        write_part(Path(out) / name / part_name(chunk), table, {**meta, "table": name, "rows": table.num_rows})
    oc = np.bincount(res.lifetimes["outcome"], minlength=3)
    return RunSummary(
        n=stop - start,
        escaped=int(oc[0]),
        settled=int(oc[1]),
        censored=int(oc[2]),
        n_sections=len(res.sections["t"]),
        n_snapshots=len(res.snapshots["t"]),
        compute_seconds=elapsed,
    )


def _decode(d):
    """Undo the JSON encoding of infinities in a scene dict."""
    sec = d.get("sections")
    if sec:
        d["sections"] = {k: (float(v) if isinstance(v, str) else v) for k, v in sec.items()}
    return d


def chunk_complete(scene: Scene, out: Path, chunk: int, start: int, stop: int) -> bool:
    """True if every part file of ``chunk`` exists, is readable, has the scene's hash and its row count."""
    import pyarrow.parquet as pq

    want = scene.result_hash()
    for name in tables_of(scene):
        p = out / name / part_name(chunk)
        if not p.exists():
            return False
        try:
            meta = read_meta(p)
            rows = pq.ParquetFile(p).metadata.num_rows
        except Exception:  # noqa: BLE001 - a damaged file is redone, whatever the damage
            return False
        if meta.get("scene_hash") != want:
            raise SceneError(
                f"cannot resume: {p} was made by a different scene (hash {meta.get('scene_hash', '?')[:12]}…, "
                f"this scene {want[:12]}…); use --overwrite or another --out"
            )
        if rows != meta.get("rows") or meta.get("orbits") != [start, stop]:
            return False
        if name == "lifetimes" and rows != stop - start:
            return False
    return True


def prepare_output(scene: Scene, out: Path, *, overwrite: bool, resume: bool):
    """Check and prepare the output directory before any work; raise SceneError if unusable."""
    if overwrite and resume:
        raise SceneError("--overwrite and --resume exclude each other")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SceneError(f"out: {out} exists and is not a directory")
    if out.exists() and any(out.iterdir()):
        if overwrite:
            for name in (*TABLES, SCENE_FILE):
                p = out / name
                if p.is_dir():
                    shutil.rmtree(p)
                elif p.exists():
                    p.unlink()
        elif resume:
            sj = out / SCENE_FILE
            if sj.exists():
                old = json.loads(sj.read_text())
                if old.get("scene_hash") != scene.result_hash():
                    raise SceneError(
                        f"cannot resume into {out}: it holds a different scene; use --overwrite or another --out"
                    )
        else:
            raise SceneError(f"out: {out} is not empty; pass --overwrite to replace it or --resume to continue it")
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise SceneError(f"out: {out} is not writable ({exc.strerror or exc})") from None
    doc = {"scene": json.loads(scene.to_json()), "scene_hash": scene.result_hash()}
    tmp = out / f".{SCENE_FILE}.tmp"
    tmp.write_text(json.dumps(doc, indent=2, sort_keys=True))
    os.replace(tmp, out / SCENE_FILE)


def default_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)


def simulate(scene: Scene, out, *, workers=None, overwrite=False, resume=False, progress=True) -> RunSummary:
    """simulate(scene, out, workers=None, overwrite=False, resume=False, progress=True) -> RunSummary.

    Writes the scene's tables under ``out`` (see :mod:`hhscatter.tables`).
    ``workers``: processes (default: all cores). Tables are byte-identical for
    any number of workers. With ``resume``, complete chunks are verified and
    kept, the rest redone.
    """
    from tqdm.auto import tqdm

    out = Path(out)
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise SceneError(f"workers must be an integer ≥ 1, got {workers!r}")
    table_ics = None
    if scene.ics is not None:
        from .ics import read_ics_table

        table_ics = read_ics_table(scene.ics)
        if len(table_ics[0]) != scene.n:
            raise SceneError(f"n = {scene.n} but the ics table has {len(table_ics[0])} rows")
    prepare_output(scene, out, overwrite=overwrite, resume=resume)
    workers = workers or default_workers()

    chunks = plan_chunks(scene)
    summary = RunSummary(workers=workers)
    todo = []
    for chunk, start, stop in chunks:
        if resume and chunk_complete(scene, out, chunk, start, stop):
            summary.chunks_skipped += 1
            continue
        todo.append((chunk, start, stop))

    scene_json = scene.to_json()
    t0 = time.perf_counter()
    done_orbits = sum(stop - start for _, start, stop in chunks) - sum(stop - start for _, start, stop in todo)
    bar = tqdm(
        total=scene.n, initial=done_orbits, unit="orbit", unit_scale=True, disable=not progress,
        desc=f"{scene.name}", smoothing=0.05,
    )

    def args(c, s, e):
        if table_ics is None:
            return (scene_json, c, s, e, str(out))
        states, ids = table_ics
        return (scene_json, c, s, e, str(out), states[s:e], ids[s:e])

    try:
        if workers == 1 or len(todo) <= 1:
            for c, s, e in todo:
                summary.add(run_one_chunk(*args(c, s, e)))
                bar.update(e - s)
        else:
            import multiprocessing as mp

            ctx = mp.get_context("spawn")  # no fork of a process holding LLVM/JIT state
            with ProcessPoolExecutor(max_workers=min(workers, len(todo)), mp_context=ctx) as pool:
                futs = {pool.submit(run_one_chunk, *args(c, s, e)): e - s for c, s, e in todo}
                for fut in as_completed(futs):
                    summary.add(fut.result())
                    bar.update(futs[fut])
    finally:
        bar.close()
    summary.wall_seconds = time.perf_counter() - t0
    return summary
