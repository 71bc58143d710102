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
  existing Dask cluster (see :mod:`hhscatter.dask_backend`).

Every task is one (point, chunk): the worker integrates it, writes its part
files straight to the output location and returns a small
:class:`RunSummary`; the client keeps at most a few tasks per worker in
flight, so its memory does not grow with N.

Crash safety. A part file appears under its final name only when complete
(temporary name, fsync, rename; :mod:`hhscatter.store`); within a chunk the
``lifetimes`` part is written last. Each part's metadata records the scene,
its hash, the chunk, its orbit range and its row count: that is the record of
finished work (no separate manifest that could disagree with the files).
``resume=True`` re-reads every existing part in full (page checksums, row
counts, scene hash), keeps the good ones, deletes temporaries left by killed
writers and redoes the rest; a run directory made by another scene is refused.
A failed write (disk full, permission lost) stops the run with a
:class:`RunError` that names the file; finished parts stay intact.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass

import numpy as np

from .scene import Scene, SceneError, scene_from_dict
from .store import Store
from .tables import TABLES, part_name, read_meta, verify_part

SCENE_FILE = "scene.json"


class RunError(RuntimeError):
    """A run could not complete (e.g. a part file could not be written); finished chunks are kept."""


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
    """plan_chunks(scene) -> [(chunk, start, stop)] covering orbits 0..n−1."""
    c = scene.chunk_size
    return [(i, s, min(s + c, scene.n)) for i, s in enumerate(range(0, scene.n, c))]


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
    from .grid import Grid

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
    from .ics import region_ics

    return region_ics(scene, start, stop), np.arange(start, stop, dtype=np.int64)


def run_one_chunk(scene_json: str, chunk: int, start: int, stop: int, out, ics=None, ids=None, partition="",
                  progress=None):
    """run_one_chunk(scene_json, chunk, start, stop, out, ics=None, ids=None, partition='', progress=None)
    -> RunSummary.

    Worker entry (local pool or Dask): integrate orbits start..stop−1 of the
    scene, write the chunk's part files under ``out`` (path or URL) and
    return the chunk's counts. An OSError while writing is re-raised naming
    the file. ``progress``: a callable f(k), or a queue that gets (chunk, k)
    (another process's), told as orbits of the chunk start.
    """
    from .engine import run_chunk
    from .tables import add_point_columns, provenance, to_arrow, write_part

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
        "scene_hash": scene.result_hash(),
        "chunk": chunk,
        "orbits": [start, stop],
        **provenance(),
    }
    rows = res.tables()
    # lifetimes last: its presence marks a complete chunk
    for name in reversed(tables_of(scene)):
        table = to_arrow(name, rows[name])
        if partition and "=" not in partition:  # a grid point's files name their point (hhscatter.tables)
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


def chunk_complete(scene: Scene, out, chunk: int, start: int, stop: int, partition: str = "") -> bool:
    """chunk_complete(scene, out, chunk, start, stop, partition='') -> bool.

    True if every part file of ``chunk`` exists, reads in full with valid page
    checksums, and has this scene's hash, orbit range and row count. Raises
    SceneError if a part was made by another scene.
    """
    store = Store(out)
    want = scene.result_hash()
    for name in tables_of(scene):
        rel = part_rel(name, partition, chunk)
        if not store.exists(rel):
            return False
        try:
            meta = read_meta(store.path(rel), filesystem=store.filesystem)
        except Exception:  # noqa: BLE001 - a damaged file is redone, whatever the damage
            return False
        if meta.get("scene_hash") != want:
            raise SceneError(
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


def prepare_output(run, out, *, overwrite: bool, resume: bool):
    """Check and prepare the output location before any work; raise SceneError if unusable."""
    if overwrite and resume:
        raise SceneError("--overwrite and --resume exclude each other")
    try:
        store = Store(out)
    except ValueError as exc:
        raise SceneError(str(exc)) from None
    if store.exists() and not store.is_dir():
        raise SceneError(f"out: {store.display()} exists and is not a directory")
    if store.listdir():
        if overwrite:
            for name in (*TABLES, SCENE_FILE):
                store.remove(name)
        elif resume:
            if store.exists(SCENE_FILE):
                old = json.loads(store.read_text(SCENE_FILE))
                if old.get("scene_hash") != run.result_hash():
                    what = _diff(old.get("scene", {}), json.loads(run.to_json()))
                    raise SceneError(
                        f"cannot resume into {store.display()}: it holds a different scene"
                        f"{' (' + what + ')' if what else ''}; use --overwrite or another --out"
                    )
            for name in TABLES:
                store.remove_temporaries(name)
        else:
            raise SceneError(
                f"out: {store.display()} is not empty; pass --overwrite to replace it or --resume to continue it"
            )
    try:
        store.makedirs()
        probe = f".write-test-{os.getpid()}"
        store.write_text(probe, "")
        store.remove(probe)
    except OSError as exc:
        raise SceneError(f"out: {store.display()} is not writable ({exc.strerror or exc})") from None
    doc = {"scene": json.loads(run.to_json()), "scene_hash": run.result_hash()}
    from .grid import Grid

    if isinstance(run, Grid):
        doc["grid"] = {"energy": list(run.energies), "gamma": list(run.gammas)}
        points = resumed_points(store, points_of(run)) if resume else points_of(run)
        doc["points"] = [{"partition": part, "scene_hash": p.result_hash()} for p, part in points]
    store.write_json(SCENE_FILE, doc)
    return store


def resumed_points(store, points):
    """resumed_points(store, points) -> points with the folder names the run at ``store`` was started with.

    A grid run begun by hhscatter ≤ 0.1.0 keeps its ``energy=…/gamma=…`` folders when resumed, so that it
    stays one dataset in one layout (:mod:`hhscatter.tables` reads both).
    """
    if not store.exists(SCENE_FILE):
        return points
    old = {p.get("scene_hash"): p.get("partition") for p in json.loads(store.read_text(SCENE_FILE)).get("points", [])}
    return [(scene, old.get(scene.result_hash()) or part) for scene, part in points]


def default_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)


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


def simulate(run, out, *, workers=None, overwrite=False, resume=False, progress=True,
             scheduler=None) -> RunSummary:
    """simulate(run, out, workers=None, overwrite=False, resume=False, progress=True, scheduler=None) -> RunSummary.

    Writes the tables of ``run`` (a Scene, or a :class:`hhscatter.grid.Grid`)
    under ``out`` (a directory or URL; see :mod:`hhscatter.tables`).
    ``workers``: processes (default: all cores; with ``scheduler='local'`` the
    LocalCluster's worker processes). ``scheduler``: None (local pool),
    ``'local'`` or a Dask scheduler address ``'tcp://host:port'``. Tables are
    byte-identical for any backend and number of workers. With ``resume``,
    complete chunks are verified and kept, the rest redone. ``progress``:
    True (a tqdm bar), ``'plain'`` (a plain line on stderr at most every 10 s,
    for logs: no carriage returns) or False.
    Raises SceneError on bad input (before any work), RunError when a chunk
    cannot be written.
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SceneError(f"workers must be an integer ≥ 1, got {workers!r}")
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler):
        raise SceneError(f"scheduler must be 'local' or a Dask scheduler address, got {scheduler!r}")
    points = points_of(run)
    table_ics = None
    if points[0][0].ics is not None:
        from .ics import read_ics_table

        scene = points[0][0]
        table_ics = read_ics_table(scene.ics)
        if len(table_ics[0]) != scene.n:
            raise SceneError(f"n = {scene.n} but the ics table has {len(table_ics[0])} rows")
    if scheduler is not None:
        from .dask_backend import check_scheduler

        check_scheduler(scheduler, workers)
    store = prepare_output(run, out, overwrite=overwrite, resume=resume)
    if resume:
        points = resumed_points(store, points)
    # workers get an absolute path (their working directory may differ) or the URL
    out_url = store.root if store.local else store.url

    summary = RunSummary()
    todo = []
    n_total = 0
    for scene, partition in points:
        scene_json = scene.to_json()
        for chunk, start, stop in plan_chunks(scene):
            n_total += stop - start
            if resume and chunk_complete(scene, store, chunk, start, stop, partition):
                summary.chunks_skipped += 1
                continue
            todo.append((scene_json, chunk, start, stop, partition))
    done_orbits = n_total - sum(t[3] - t[2] for t in todo)

    def args(task):
        scene_json, c, s, e, partition = task
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
        if not todo:
            summary.workers = 0
        elif scheduler is not None:
            from .dask_backend import dask_client

            with dask_client(scheduler, workers) as client:
                summary.workers = sum(client.nthreads().values())
                summary.backend = f"dask {scheduler}" if scheduler != "local" else "dask LocalCluster"
                _run_dask(client, todo, args, on_done, run.name)
        else:
            workers = workers or default_workers()
            summary.workers = workers
            if workers == 1 or len(todo) <= 1:
                for task in todo:
                    key = (task[4], task[1])
                    tell = (lambda k, key=key: on_progress(key, k)) if progress else None
                    on_done(task, run_one_chunk(*args(task), progress=tell))
            else:
                _run_pool(workers, todo, args, on_done, on_progress if progress else None)
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
        import sys

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
    import sys

    if progress == "plain" or (progress and not sys.stderr.isatty() and "ipykernel" not in sys.modules):
        return PlainProgress(total, initial, desc)
    if not progress:
        return _Silent()
    import importlib.util

    if sys.stderr.isatty() or importlib.util.find_spec("ipywidgets") is None:
        from tqdm.std import tqdm  # text bar (tqdm.auto would warn in a kernel without ipywidgets)
    else:
        from tqdm.auto import tqdm

    return tqdm(total=total, initial=initial, unit="orbit", unit_scale=True, desc=desc, smoothing=0.05)


class _Silent:
    def update(self, n=1):
        pass

    def close(self):
        pass


def _run_pool(workers, todo, args, on_done, on_progress=None):
    import multiprocessing as mp
    import queue as queue_mod
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    ctx = mp.get_context("spawn")  # no fork of a process holding LLVM/JIT state
    pool = ProcessPoolExecutor(max_workers=min(workers, len(todo)), mp_context=ctx)
    manager = ctx.Manager() if on_progress is not None else None
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
        _drain(lambda t: pool.submit(run_one_chunk, *args(t), progress=q),
               wait_first, todo, 2 * workers, on_done,
               lambda fs: [f.cancel() for f in fs])
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        if manager is not None:
            manager.shutdown()


def _run_dask(client, todo, args, on_done, name):
    import uuid

    from distributed import wait

    window = max(4, 2 * sum(client.nthreads().values()))
    tag = uuid.uuid4().hex[:8]

    def submit(task):
        key = f"hhscatter-{name}-{task[4].replace('/', ',') + '-' if task[4] else ''}{task[1]}-{tag}"
        return client.submit(run_one_chunk, *args(task), key=key, pure=False, retries=0)

    _drain(submit, lambda fs: wait(fs, return_when="FIRST_COMPLETED").done, todo, window, on_done,
           lambda fs: client.cancel(fs))
