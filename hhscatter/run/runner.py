"""Run a scene or a grid: chunk planning, backends, part files, resume, progress.

``simulate(run, out, workers=None, overwrite=False, resume=False, scheduler=None)``
checks everything it can before any work (output location writable and empty
or explicitly overwritten/resumed, initial conditions valid), then integrates
the chunks and writes one part file per chunk and table.

Backends (results are byte-identical whichever runs the chunks):

* ``workers=1``: in this process;
* default: a local process pool (``workers`` processes, default all cores);
* ``scheduler='local'``: a ``dask.distributed.LocalCluster`` of ``workers``
  single-threaded worker processes; ``scheduler='tcp://HOST:PORT'``: an
  existing Dask cluster (see :mod:`hhscatter.run.dask_backend`).

Every task is one (point, chunk): the worker integrates it, writes its part
files straight to the output location and returns a small
:class:`RunSummary`; the client keeps at most a few tasks per worker in
flight, so its memory does not grow with N.

Crash safety. A part file appears under its final name only when complete
(temporary name, fsync, rename; :mod:`hhscatter.data.store`); within a chunk the
``lifetimes`` part is written last. Each part's metadata records the scene,
its hash, the chunk, its orbit range and its row count.
``resume=True`` re-reads every existing part in full (page checksums, row
counts, scene hash), keeps the good ones, deletes temporaries left by killed
writers and redoes the rest; a run directory made by another scene, or holding
part files outside the chunk plan, is refused.
A failed write (disk full, permission lost) stops the run with a
:class:`RunError` that names the file; finished parts stay intact.

A run is a manifest. ``scene.json`` holds the plan (:func:`manifest_of`: the
tables, and per point its scene hash, n and chunk size, hence every part file
and its orbit range); the readers of :mod:`hhscatter.data.schema` read exactly the
planned parts whose chunk is finished, check each part's metadata against the
plan and verify the page checksums, and refuse anything else. An unfinished
chunk (no ``lifetimes`` part) makes the run incomplete: an error for readers
unless they pass ``allow_partial=True``.

One writer per run directory: ``simulate`` holds an exclusive ``flock`` on
``OUT/.hhscatter.lock`` (:meth:`hhscatter.data.store.Store.lock`) from its checks to
its end; the kernel releases it however the process ends. ``overwrite=True``
removes the old run (its tables, scene.json, temporaries) under that lock
before anything is written. Pool workers (and the progress manager) die with
the process that started them (:func:`die_with_parent`); a Dask run whose
cluster has had no worker for :data:`DASK_NO_WORKER_TIMEOUT` seconds fails with
a :class:`RunError`.
"""
from __future__ import annotations

import importlib.util
import json
import multiprocessing as mp
import os
import queue as queue_mod
import shutil
import signal
import sys
import threading
import time
import uuid
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass
from multiprocessing.managers import SyncManager
from typing import TYPE_CHECKING

import numpy as np

from hhscatter.data.store import LOCK_FILE, TMP_MARK, LockedError, Store
from hhscatter.data.schema import TABLES, add_point_columns, part_name, provenance, to_arrow
from hhscatter.data.read import read_meta, verify_part
from hhscatter.data.write import write_part
from hhscatter.errors import ConfigError, OutputError, RunError, RunIntegrityError  # noqa: F401 (RunError: re-exported)
from hhscatter.integrate.engine import run_chunk
from hhscatter.run.dask_backend import check_scheduler, dask_client
from hhscatter.run.workers import default_workers
from hhscatter.scene.grid import Grid
from hhscatter.scene.ics import check_ics, read_ics_table, region_ics
from hhscatter.scene.scene import Scene, scene_from_dict

if TYPE_CHECKING:  # annotations only (grid imports runner's neighbours)
    from hhscatter.scene.grid import Grid

SCENE_FILE = "scene.json"
#: seconds a Dask run waits with no worker in the cluster before it fails (hhscatter.run.runner._run_dask)
DASK_NO_WORKER_TIMEOUT = 60.0


@dataclass
class RunSummary:
    """Counts per outcome and timings of a run (or of one chunk)."""

    n: int = 0
    escaped: int = 0
    settled: int = 0
    censored: int = 0
    stopped: int = 0
    n_sections: int = 0
    n_snapshots: int = 0
    compute_seconds: float = 0.0  # time spent in chunks, summed over workers
    wall_seconds: float = 0.0
    chunks_done: int = 0
    chunks_skipped: int = 0
    workers: int = 1
    backend: str = "local"

    def add(self, other: RunSummary):
        for k in ("n", "escaped", "settled", "censored", "stopped", "n_sections", "n_snapshots", "compute_seconds"):
            setattr(self, k, getattr(self, k) + getattr(other, k))
        self.chunks_done += 1

    def line(self) -> str:
        if self.n == 0 and self.chunks_skipped:
            return f"nothing to do: all {self.chunks_skipped} chunk(s) verified complete and kept"
        us = 1e6 * self.wall_seconds / max(self.n, 1)
        us_core = 1e6 * self.compute_seconds / max(self.n, 1)
        skipped = f", {self.chunks_skipped} chunk(s) resumed" if self.chunks_skipped else ""
        where = "" if self.backend == "local" else f" on {self.backend}"
        return (
            f"{self.n} orbits: escaped {self.escaped}, settled {self.settled}, censored {self.censored}"
            f"{f', stopped {self.stopped}' if self.stopped else ''}"
            f" | wall {self.wall_seconds:.2f} s ({us:.2f} µs per orbit; {us_core:.2f} µs per orbit in the workers' chunks)"
            f" ({self.workers} worker{'s' if self.workers != 1 else ''}{where}{skipped})"
        )


def plan_chunks(scene: Scene):
    """plan_chunks(scene) -> iterator of (chunk, start, stop) covering orbits 0..n−1 (made lazily: no list
    of one tuple per chunk is held)."""
    c, n = scene.chunk_size, scene.n
    return ((i, s, min(s + c, n)) for i, s in enumerate(range(0, n, c)))


def tables_of(scene: Scene):
    names = ["lifetimes"]
    if scene.sections is not None:
        names.append("sections")
    if scene.snapshots:
        names.append("snapshots")
    if scene.follow is not None:
        names.append("crossings")
    return names


def points_of(run):
    """points_of(run) -> [(scene, partition)]: ('', the scene) for a Scene, one per grid point for a Grid."""
    if isinstance(run, Grid):
        return [(p, Grid.partition(p)) for p in run.points]
    return [(run, "")]


def part_rel(name: str, partition: str, chunk: int) -> str:
    """Relative path of a part file: '<table>/[<partition>/]part-<chunk>.parquet'."""
    return "/".join(x for x in (name, partition, part_name(chunk)) if x)


def _chunk_ics(scene, start, stop, table_ics):
    if table_ics is not None:
        states, ids = table_ics
        return states[start:stop], ids[start:stop]

    return region_ics(scene, start, stop), np.arange(start, stop, dtype=np.int64)


def run_one_chunk(scene_json: str, chunk: int, start: int, stop: int, out, ics=None, ids=None, partition="",
                  progress=None, scene_hash=None):
    """run_one_chunk(scene_json, chunk, start, stop, out, ics=None, ids=None, partition='', progress=None,
    scene_hash=None) -> RunSummary.

    Worker entry (local pool or Dask): integrate orbits start..stop−1 of the
    scene, write the chunk's part files under ``out`` (path or URL) and
    return the chunk's counts. An OSError while writing is re-raised naming
    the file. ``progress``: a callable f(k), or a queue that gets (chunk, k)
    (another process's), told as orbits of the chunk start. ``scene_hash``: the scene's result hash as
    the client computed it once per run (default: computed here, which re-reads an IC table).
    """

    scene = scene_from_dict(_decode(json.loads(scene_json)))
    store = Store(out)
    if ics is None:
        ics, ids = _chunk_ics(scene, start, stop, None)
    if progress is not None and not callable(progress):
        queue, key = progress, (partition, chunk)
        progress = lambda k: queue.put((key, k))  # noqa: E731 - a queue proxy of the parent's Manager
    t0 = time.perf_counter()
    res = run_chunk(scene, ics, ids, progress=progress)
    elapsed = time.perf_counter() - t0
    meta = {
        "scene": json.loads(scene_json),
        "scene_hash": scene_hash or scene.result_hash(),
        "chunk": chunk,
        "orbits": [start, stop],
        **provenance(),
    }
    rows = res.tables()
    # lifetimes last: its presence marks a complete chunk
    for name in reversed(tables_of(scene)):
        table = to_arrow(name, rows[name])
        if partition and "=" not in partition:  # a grid point's files name their point (hhscatter.data.schema)
            table = add_point_columns(name, table, scene)
        rel = part_rel(name, partition, chunk)
        try:
            write_part(rel, table, {**meta, "table": name, "rows": table.num_rows}, store=store)
        except OSError as exc:
            raise OSError(exc.errno, f"cannot write {store.display(rel)}: {exc.strerror or exc}") from None
    oc = np.bincount(res.lifetimes["outcome"], minlength=4)
    return RunSummary(
        n=stop - start,
        escaped=int(oc[0]),
        settled=int(oc[1]),
        censored=int(oc[2]),
        stopped=int(oc[3]),
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


def chunk_complete(scene: Scene, out, chunk: int, start: int, stop: int, partition: str = "", want=None) -> bool:
    """chunk_complete(scene, out, chunk, start, stop, partition='', want=None) -> bool.

    True if every part file of ``chunk`` exists, reads in full with valid page
    checksums, and has this scene's hash, orbit range and row count. Raises
    RunIntegrityError if a part was made by another scene.
    """
    store = Store(out)
    want = want or scene.result_hash()
    for name in tables_of(scene):
        rel = part_rel(name, partition, chunk)
        if not store.exists(rel):
            return False
        try:
            meta = read_meta(store.path(rel), filesystem=store.filesystem)
        except Exception:  # noqa: BLE001 - a damaged file is redone, whatever the damage
            return False
        if meta.get("scene_hash") != want:
            raise RunIntegrityError(
                f"cannot resume: {store.display(rel)} was made by a different scene (hash "
                f"{str(meta.get('scene_hash', '?'))[:12]}…, this scene {want[:12]}…); "
                "use --overwrite or another --out"
            )
        if meta.get("orbits") != [start, stop] or meta.get("chunk") != chunk:
            return False
        source = store.open_input(rel)
        try:
            verify_part(source, expect_rows=stop - start if name == "lifetimes" else None)
        except Exception:  # noqa: BLE001 - truncated, damaged page, wrong row count: redo
            return False
        finally:
            if not isinstance(source, str):
                source.close()
    return True


def _diff(old: dict, new: dict) -> str:
    keys = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k) and k not in ("name", "batch_size"))
    return ", ".join(f"{k}: {old.get(k)!r} → {new.get(k)!r}" for k in keys[:6])


def manifest_of(points, tables) -> dict:
    """manifest_of([(scene, partition, scene_hash)], tables) -> the run's plan, as stored in scene.json.

    ``{"tables": [...], "points": [{"partition", "scene_hash", "n", "chunk_size"}]}``: the part files a
    complete run has are exactly part_rel(table, partition, chunk) for chunk < ceil(n/chunk_size), each
    carrying ``scene_hash`` and its orbit range in its metadata (:func:`hhscatter.data.read.run_parts`).
    """
    return {"tables": list(tables),
            "points": [{"partition": part, "scene_hash": h, "n": int(sc.n), "chunk_size": int(sc.chunk_size)}
                       for sc, part, h in points]}


def _extra_parts(store, manifest) -> list[str]:
    """Part files under the table folders that the manifest does not plan (duplicates, junk, other runs)."""
    planned = {part_rel(name, p["partition"], c) for name in manifest["tables"] for p in manifest["points"]
               for c in range(-(-p["n"] // p["chunk_size"]))}
    extra = []
    for name in TABLES:
        for f in store.files(name):
            base = f.rsplit("/", 1)[-1]
            if base.startswith(".") and TMP_MARK in base:
                continue
            if f"{name}/{f}" not in planned:
                extra.append(f"{name}/{f}")
    return extra


def prepare_output(run, out, *, overwrite: bool, resume: bool, points=None):
    """Check and prepare the output location before any work; raise OutputError if unusable.

    Takes the run directory's write lock (one writer per directory, :meth:`hhscatter.data.store.Store.lock`):
    returns (store, lock, points), the lock to be released with ``Store.unlock`` when the run ends. ``points``:
    [(scene, partition, scene_hash)] (default: from ``run``). If a check fails, nothing is left behind
    (a directory made here is removed again).
    """
    if overwrite and resume:
        raise ConfigError("--overwrite and --resume exclude each other")
    try:
        store = Store(out)
    except ValueError as exc:
        raise OutputError(str(exc)) from None
    if store.exists() and not store.is_dir():
        raise OutputError(f"out: {store.display()} exists and is not a directory")
    if points is None:
        points = [(sc, part, sc.result_hash()) for sc, part in points_of(run)]
    created = not store.exists()
    lock = None
    try:
        try:
            lock = store.lock()
        except LockedError as exc:
            raise OutputError(f"out: {exc}; one writer per run directory: wait for it or use another --out") \
                from None
        except OSError as exc:
            raise OutputError(f"out: {store.display()} is not writable ({exc.strerror or exc})") from None
        # ours to remove on failure only if it was not there and still holds nothing but our lock
        created = created and not [e for e in store.listdir() if e != LOCK_FILE]
        _check_and_clear(run, store, points, overwrite=overwrite, resume=resume)
        if resume:
            points = resumed_points(store, points)
        try:
            store.makedirs()
            probe = f".write-test-{os.getpid()}"
            store.write_text(probe, "")
            store.remove(probe)
        except OSError as exc:
            raise OutputError(f"out: {store.display()} is not writable ({exc.strerror or exc})") from None
        doc = {"scene": json.loads(run.to_json()), "scene_hash": run.result_hash()}

        if isinstance(run, Grid):
            doc["grid"] = {"energy": list(run.energies), "gamma": list(run.gammas)}
            doc["points"] = [{"partition": part, "scene_hash": h} for _, part, h in points]
        doc["manifest"] = manifest_of(points, tables_of(points[0][0]))
        try:
            store.write_json(SCENE_FILE, doc)
        except OSError as exc:
            raise OutputError(f"out: cannot write {store.display(SCENE_FILE)} ({exc.strerror or exc}); "
                             "nothing was computed") from None
    except BaseException:
        if lock is not None and created:  # never a directory another writer made or holds

            shutil.rmtree(store.root, ignore_errors=True)
        Store.unlock(lock)
        raise
    return store, lock, points


def _check_and_clear(run, store, points, *, overwrite, resume):
    """The emptiness / same-scene checks of prepare_output, under the lock; --overwrite clears the old run."""
    entries = [e for e in store.listdir() if e != LOCK_FILE]
    if not entries:
        return
    if overwrite:
        # the whole old run: its tables, its scene, its temporaries (other files are not ours: kept)
        for name in entries:
            if name in (*TABLES, SCENE_FILE) or (name.startswith(".") and TMP_MARK in name):
                store.remove(name)
        return
    if not resume:
        raise OutputError(
            f"out: {store.display()} is not empty; pass --overwrite to replace it or --resume to continue it"
        )
    if store.exists(SCENE_FILE):
        old = json.loads(store.read_text(SCENE_FILE))
        if old.get("scene_hash") != run.result_hash():
            what = _diff(old.get("scene", {}), json.loads(run.to_json()))
            raise OutputError(
                f"cannot resume into {store.display()}: it holds a different scene"
                f"{' (' + what + ')' if what else ''}; use --overwrite or another --out"
            )
    extra = _extra_parts(store, manifest_of(resumed_points(store, points), tables_of(points[0][0])))
    if extra:
        raise OutputError(
            f"cannot resume into {store.display()}: {len(extra)} part file(s) are not in this run's chunk plan "
            f"(first: {store.display(extra[0])}); remove them, or use --overwrite or another --out"
        )
    for name in TABLES:
        store.remove_temporaries(name)


def resumed_points(store, points):
    """resumed_points(store, points) -> points with the folder names the run at ``store`` was started with.

    A grid run begun by hhscatter ≤ 0.1.0 keeps its ``energy=…/gamma=…`` folders when resumed, so that it
    stays one dataset in one layout (:mod:`hhscatter.data.schema` reads both).
    """
    if not store.exists(SCENE_FILE):
        return points
    old = {p.get("scene_hash"): p.get("partition") for p in json.loads(store.read_text(SCENE_FILE)).get("points", [])}
    if points and len(points[0]) == 3:
        return [(scene, old.get(h) or part, h) for scene, part, h in points]
    return [(scene, old.get(scene.result_hash()) or part) for scene, part in points]


def _drain(submit, wait_first, tasks, window, on_done, cancel):
    """Run ``tasks`` keeping at most ``window`` in flight; on_done(task, result) as each finishes.

    On any error the tasks not yet finished are cancelled (``cancel``) and the
    error propagates; finished tasks have already been reported.
    """
    it = iter(tasks)
    pending = {}
    try:
        for task in it:
            pending[submit(task)] = task
            if len(pending) >= window:
                break
        while pending:
            for fut in wait_first(list(pending)):
                task = pending.pop(fut)
                on_done(task, fut.result())
                nxt = next(it, None)
                if nxt is not None:
                    pending[submit(nxt)] = nxt
    except BaseException:
        cancel(list(pending))
        raise


def simulate(run: Scene | Grid, out: str | os.PathLike[str], *, workers: int | None = None,
             overwrite: bool = False, resume: bool = False, progress: bool | str = True,
             scheduler: str | None = None) -> RunSummary:
    """Integrate an ensemble and write its tables (lifetimes, and sections/snapshots if asked) as Parquet.

    Every orbit runs to its end by exact events: escape at r = r_esc (then followed to r_far for the
    no-return rule), settling at E = E_c inside Ω with drag (Eq. (eqn:energy_diffeq)), or t_max (censored);
    the Hamiltonian flow of Eq. (eq:H) with the potential of Eq. (eqn:hh_potential) and drag −γp.

    Parameters
    ----------
    run : Scene or Grid
        What to integrate: one ensemble, or a sweep over E0 and/or γ (:class:`hhscatter.Grid`).
    out : path or URL
        Output directory (created), or a URL pyarrow/fsspec can write (``s3://…``); see
        :mod:`hhscatter.data.schema` for the layout.
    workers : int, optional
        Processes (default: all cores; with ``scheduler='local'``, the LocalCluster's worker processes).
    overwrite : bool
        Replace the tables of a non-empty ``out`` (the old run is removed first, under the run's lock).
    resume : bool
        Verify and keep the complete chunks of an interrupted run of the same scene; redo the rest.
    progress : bool or 'plain'
        True: a tqdm bar on a terminal; ``'plain'``: a plain line on stderr at most every 10 s (for logs);
        False: none.
    scheduler : str, optional
        None (local process pool), ``'local'`` (a Dask LocalCluster) or a Dask scheduler address
        ``'tcp://host:port'``.

    Returns
    -------
    RunSummary
        Orbits per outcome, rows written, compute and wall seconds, chunks done and resumed.

    Raises
    ------
    ConfigError
        Bad input, before any work and before anything is written (exit 2 on the CLI).
    OutputError
        The output location cannot take the run (not empty, another scene, locked, not writable); exit 2.
    RunError
        A chunk cannot be written (e.g. a full disk), or a Dask cluster lost all its workers.

    Notes
    -----
    Tables are byte-identical for any backend, number of workers and chunk size: the seed and the orbit
    index fix every orbit.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> summary = hhscatter.simulate(hhscatter.Scene(energy=0.3, n=200, seed=1, t_max=200.0),
    ...                              tempfile.mkdtemp(), workers=1, progress=False)
    >>> summary.n, summary.escaped + summary.settled + summary.censored
    (200, 200)
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ConfigError(f"workers must be an integer ≥ 1, got {workers!r}")
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler):
        raise ConfigError(f"scheduler must be 'local' or a Dask scheduler address, got {scheduler!r}")
    points = points_of(run)
    table_ics = None
    if points[0][0].ics is not None:

        scene = points[0][0]
        table_ics = read_ics_table(scene.ics)
        if len(table_ics[0]) != scene.n:
            raise ConfigError(f"n = {scene.n} but the ics table has {len(table_ics[0])} rows")
        for sc, _ in points:
            check_ics(sc, table_ics[0])
    if scheduler is not None:

        check_scheduler(scheduler, workers)
    # every point's result hash once per run (an IC table is read and hashed here, not per chunk)
    points = [(sc, part, sc.result_hash()) for sc, part in points]
    store, lock, points = prepare_output(run, out, overwrite=overwrite, resume=resume, points=points)
    try:
        return _simulate(run, store, points, table_ics, workers, resume, progress, scheduler)
    finally:
        Store.unlock(lock)


def _simulate(run, store, points, table_ics, workers, resume, progress, scheduler) -> RunSummary:
    # workers get an absolute path (their working directory may differ) or the URL
    out_url = store.root if store.local else store.url

    summary = RunSummary()
    n_total = sum(sc.n for sc, _, _ in points)
    n_chunks = sum(-(-sc.n // sc.chunk_size) for sc, _, _ in points)
    todo = []
    if resume:  # verify the finished chunks first: the bar then starts where the run stopped
        for scene, partition, h in points:
            scene_json = scene.to_json()
            for chunk, start, stop in plan_chunks(scene):
                if chunk_complete(scene, store, chunk, start, stop, partition, want=h):
                    summary.chunks_skipped += 1
                    continue
                todo.append((scene_json, chunk, start, stop, partition, h))
        done_orbits = n_total - sum(t[3] - t[2] for t in todo)
        n_todo = len(todo)
    else:  # planned lazily: one task tuple per chunk in flight, not per chunk of the run
        todo = ((sj, chunk, start, stop, partition, h) for scene, partition, h in points
                for sj in (scene.to_json(),) for chunk, start, stop in plan_chunks(scene))
        done_orbits, n_todo = 0, n_chunks

    def args(task):
        scene_json, c, s, e, partition, _ = task
        if table_ics is None:
            return (scene_json, c, s, e, out_url, None, None, partition)
        states, ids = table_ics
        return (scene_json, c, s, e, out_url, states[s:e], ids[s:e], partition)

    t0 = time.perf_counter()
    bar = progress_bar(progress, n_total, done_orbits, run.name)

    reported = {}  # orbits of an unfinished chunk already shown (progress from inside chunks)

    def on_done(task, result):
        summary.add(result)
        bar.update(max(0, task[3] - task[2] - reported.pop((task[4], task[1]), 0)))

    def on_progress(key, k):
        reported[key] = reported.get(key, 0) + k
        bar.update(k)

    try:
        if not n_todo:
            summary.workers = 0
        elif scheduler is not None:

            with dask_client(scheduler, workers) as client:
                summary.workers = sum(client.nthreads().values())
                summary.backend = f"dask {scheduler}" if scheduler != "local" else "dask LocalCluster"
                _run_dask(client, todo, args, on_done, run.name)
        else:
            workers = workers or default_workers()
            summary.workers = workers
            if workers == 1 or n_todo <= 1:
                for task in todo:
                    key = (task[4], task[1])
                    tell = (lambda k, key=key: on_progress(key, k)) if progress else None
                    on_done(task, run_one_chunk(*args(task), progress=tell, scene_hash=task[5]))
            else:
                _run_pool(min(workers, n_todo), todo, args, on_done, on_progress if progress else None)
    except OSError as exc:
        raise RunError(
            f"{exc.strerror or exc}; stopped after {summary.chunks_done} new chunk(s). Finished part files "
            f"are intact: fix the cause and rerun with --resume to do only what is missing"
        ) from exc
    finally:
        bar.close()
    summary.wall_seconds = time.perf_counter() - t0
    return summary


class PlainProgress:
    """Progress for logs: a plain line on stderr at most every ``every`` seconds and at the end, no '\\r'."""

    def __init__(self, total, initial=0, desc="", every=10.0, file=None):
        self.total, self.n, self.desc, self.every = total, initial, desc, every
        self.file = file or sys.stderr
        self.t0 = self.last = time.perf_counter()

    def update(self, k):
        self.n += k
        now = time.perf_counter()
        if now - self.last >= self.every or self.n >= self.total:
            self.last = now
            print(f"{self.desc}: {self.n}/{self.total} orbits ({100 * self.n / max(self.total, 1):.0f} %), "
                  f"{now - self.t0:.0f} s", file=self.file, flush=True)

    def close(self):
        pass


def progress_bar(progress, total, initial, desc):
    """progress_bar(progress, total, initial, desc) -> object with update(n)/close(): tqdm, PlainProgress or silent.

    ``progress=True`` draws a tqdm bar only where one can be seen: on a terminal (stderr a TTY) or in a
    Jupyter kernel (a widget if ipywidgets is installed, else text); into a log file or a pipe it writes the
    plain lines of ``'plain'`` instead (no carriage returns). ``False``: silent, tqdm not even imported.
    """
    if progress == "plain" or (progress and not sys.stderr.isatty() and "ipykernel" not in sys.modules):
        return PlainProgress(total, initial, desc)
    if not progress:
        return _Silent()

    if sys.stderr.isatty() or importlib.util.find_spec("ipywidgets") is None:
        from tqdm.std import tqdm  # text bar (tqdm.auto would warn in a kernel without ipywidgets)  # deferred: tqdm loads on first use
    else:
        from tqdm.auto import tqdm  # deferred: tqdm loads on first use

    return tqdm(total=total, initial=initial, unit="orbit", unit_scale=True, desc=desc, smoothing=0.05)


class _Silent:
    def update(self, n=1):
        pass

    def close(self):
        pass


def die_with_parent(parent_pid: int) -> None:
    """die_with_parent(parent_pid) -> None: make this (worker) process die when its parent does.

    Linux: ``prctl(PR_SET_PDEATHSIG, SIGKILL)``, which the kernel applies however the parent ends
    (SIGTERM, SIGINT, kill -9), so no worker keeps computing and writing parts for a run that is gone.
    Elsewhere: a daemon thread that polls the parent every second. The pool's and the progress
    manager's initializer.
    """
    if sys.platform.startswith("linux"):
        import ctypes  # deferred: Linux-only (prctl), imported where it is used

        PR_SET_PDEATHSIG = 1
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
            if os.getppid() != parent_pid:  # the parent died before prctl: nobody will signal us
                os._exit(1)
            return

    def watch():
        while True:
            time.sleep(1.0)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, daemon=True, name="hhscatter-parent-watch").start()


def _run_pool(workers, todo, args, on_done, on_progress=None):
    ctx = mp.get_context("spawn")  # no fork of a process holding LLVM/JIT state
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=die_with_parent,
                               initargs=(os.getpid(),))
    manager = None
    if on_progress is not None:
        manager = SyncManager(ctx=ctx)
        manager.start(initializer=die_with_parent, initargs=(os.getpid(),))
    q = manager.Queue() if manager is not None else None

    def relay():
        while q is not None:
            try:
                key, k = q.get_nowait()
            except queue_mod.Empty:
                return
            on_progress(key, k)

    def wait_first(fs):
        while True:  # progress messages from inside the chunks every 0.5 s at most
            done = wait(fs, timeout=0.5 if q is not None else None, return_when=FIRST_COMPLETED).done
            relay()
            if done:
                return done

    try:
        _drain(lambda t: pool.submit(run_one_chunk, *args(t), progress=q, scene_hash=t[5]),
               wait_first, todo, 2 * workers, on_done,
               lambda fs: [f.cancel() for f in fs])
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        if manager is not None:
            manager.shutdown()


def _run_dask(client, todo, args, on_done, name):
    from distributed import wait  # deferred: distributed loads on first use

    window = max(4, 2 * sum(client.nthreads().values()))
    tag = uuid.uuid4().hex[:8]

    def submit(task):
        key = f"hhscatter-{name}-{task[4].replace('/', ',') + '-' if task[4] else ''}{task[1]}-{tag}"
        return client.submit(run_one_chunk, *args(task), key=key, pure=False, retries=0, scene_hash=task[5])

    def wait_first(fs):
        alone_since = None
        while True:
            try:
                return wait(fs, timeout=2.0, return_when="FIRST_COMPLETED").done
            except TimeoutError:
                pass
            if client.nthreads():
                alone_since = None
            elif alone_since is None:
                alone_since = time.monotonic()
            elif time.monotonic() - alone_since > DASK_NO_WORKER_TIMEOUT:
                raise RunError(
                    f"the Dask cluster has had no workers for {DASK_NO_WORKER_TIMEOUT:g} s; stopped. Finished "
                    "part files are intact: start workers and rerun with --resume")

    _drain(submit, wait_first, todo, window, on_done, lambda fs: client.cancel(fs))
