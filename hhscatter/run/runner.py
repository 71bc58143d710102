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
unless they pass ``allow_partial=True``. When the run ends, ``scene.json`` also
gets ``event_failures``: heyoka's event-detection failures per chunk (an event
heyoka ignored in a step; :mod:`hhscatter.integrate.heyoka_log`) and the orbits
redone because of them (zero counts included: the key says they were checked).

One writer per run directory: ``simulate`` holds an exclusive ``flock`` on
``OUT/.hhscatter.lock`` (:meth:`hhscatter.data.store.Store.lock`) from its checks to
its end; the kernel releases it however the process ends. ``overwrite=True``
removes the old run (its tables, scene.json, temporaries) under that lock
before anything is written. Pool workers (and the progress manager) die with
the process that started them (:func:`die_with_parent`). A new run (not ``resume``) that fails or is interrupted
before its first chunk is written leaves nothing behind (:func:`~hhscatter.run.output.discard_failed_start`:
its ``scene.json`` and lock note, and the folder if the run made it), so the same command can simply be run
again; once a chunk is written, the run is kept for ``--resume``. A Dask run whose
cluster has had no worker for :data:`DASK_NO_WORKER_TIMEOUT` seconds fails with
a :class:`RunError`.
"""

from __future__ import annotations

import contextlib
import json
import multiprocessing as mp
import os
import queue as queue_mod
import signal
import time
import uuid
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from multiprocessing.managers import SyncManager
from typing import NamedTuple

from hhscatter.data.store import Store
from hhscatter.errors import ConfigError, RunError
from hhscatter.run.dask_backend import check_scheduler, dask_client
from hhscatter.run.output import discard_failed_start, prepare_output
from hhscatter.run.plan import SCENE_FILE, RunSummary, plan_chunks, points_of
from hhscatter.run.progress import progress_bar
from hhscatter.run.worker import (
    chunk_complete,
    default_workers,
    die_with_parent,
    kept_tangent_beyond,
    pack_point,
    run_one_chunk,
)
from hhscatter.scene.grid import Grid
from hhscatter.scene.ics import check_ics, read_ics_table
from hhscatter.scene.scene import Scene


class ChunkTask(NamedTuple):
    """One task of a run: the orbits start..stop−1 of one point's scene, chunk ``chunk`` of its plan."""

    scene_json: str  # the point's scene (Scene.to_json), as its parts' metadata records it
    chunk: int
    start: int
    stop: int
    partition: str  # the grid point's folder ('' for a single scene)
    scene_hash: str  # the point's result hash, computed once per run
    plan: bytes | None = None  # the point's scene and engine plan, pickled once per run (worker.pack_point)


#: seconds a Dask run waits with no worker in the cluster before it fails (hhscatter.run.runner._run_dask)
DASK_NO_WORKER_TIMEOUT = 60.0
#: at most WORKERS_MAX worker processes: each is a process with its own JIT-compiled integrator
WORKERS_MAX = 1024


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


def simulate(
    run: Scene | Grid,
    out: str | os.PathLike[str],
    *,
    workers: int | None = None,
    overwrite: bool = False,
    resume: bool = False,
    progress: bool | str = True,
    scheduler: str | None = None,
) -> RunSummary:
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
        Processes (default: all cores; with ``scheduler='local'``, the LocalCluster's worker processes); at most
        the CPUs this process may use (its affinity mask): a larger number runs that many (the CLI says so).
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
    if not isinstance(run, (Scene, Grid)):
        raise ConfigError(
            f"run must be a Scene or a Grid (hhscatter.Scene(...), hhscatter.load_run(file)), got {type(run).__name__}"
        )
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ConfigError(f"workers must be an integer ≥ 1, got {workers!r}")
    if workers is not None and workers > WORKERS_MAX:
        raise ConfigError(
            f"workers must be ≤ {WORKERS_MAX}, got {workers} (one process each, with its own compiled integrator)"
        )
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler):
        raise ConfigError(f"scheduler must be 'local' or a Dask scheduler address, got {scheduler!r}")
    if workers is not None and scheduler in (None, "local"):  # processes beyond the CPUs only compete for them
        workers = min(workers, default_workers())
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
    # every point's engine plan once per run, here where its scene is accepted: pickled with the scene and
    # handed to every chunk (worker processes and Dask unpickle it; nothing is rebuilt there)
    packed = {part: pack_point(sc) for sc, part, _ in points}
    earlier = _earlier_event_failures(out) if resume else {}
    created = not Store(out).exists()
    store, lock, points = prepare_output(run, out, overwrite=overwrite, resume=resume, points=points)
    try:
        summary = _simulate(run, store, points, table_ics, workers, resume, progress, scheduler, earlier, packed)
        _record_event_failures(store, summary)
        return summary
    except BaseException:
        if not resume:  # a start that failed before any chunk finished leaves nothing behind
            discard_failed_start(store, remove_root=created)
        raise
    finally:
        Store.unlock(lock)


def _earlier_event_failures(out) -> dict:
    """The per-chunk event-failure counts of the run in ``out`` (its scene.json), kept when it is resumed."""
    try:
        store = Store(out)
        if not store.exists(SCENE_FILE):
            return {}
        return dict(json.loads(store.read_text(SCENE_FILE)).get("event_failures", {}).get("chunks", {}))
    except (OSError, ValueError, AttributeError):
        return {}


def _record_event_failures(store, summary) -> None:
    """Write the run's heyoka event-detection failures (per chunk, and the orbits redone) into its scene.json."""
    doc = json.loads(store.read_text(SCENE_FILE))
    doc["event_failures"] = summary.event_failures_record()
    if summary.tangent_beyond:  # orbits whose log-stretch passed the tangent dynamics' MAX_LOG_STRETCH
        doc["tangent_beyond"] = summary.tangent_beyond
    else:  # none in the chunks run or kept: a count from before a resume that redid its chunks goes
        doc.pop("tangent_beyond", None)
    store.write_json(SCENE_FILE, doc)


def _simulate(
    run, store, points, table_ics, workers, resume, progress, scheduler, earlier=None, packed=None
) -> RunSummary:
    # workers get an absolute path (their working directory may differ) or the URL
    out_url = store.root if store.local else store.url

    summary = RunSummary(event_failures=dict(earlier or {}))
    packed = packed or {}
    n_total = sum(sc.n for sc, _, _ in points)
    n_chunks = sum(-(-sc.n // sc.chunk_size) for sc, _, _ in points)
    todo = []
    if resume:  # verify the finished chunks first: the bar then starts where the run stopped
        for scene, partition, h in points:
            scene_json = scene.to_json()
            for chunk, start, stop in plan_chunks(scene):
                if chunk_complete(scene, store, chunk, start, stop, partition, want=h):
                    summary.chunks_skipped += 1
                    summary.tangent_beyond += kept_tangent_beyond(store, chunk, partition)
                    continue
                todo.append(ChunkTask(scene_json, chunk, start, stop, partition, h, packed.get(partition)))
        done_orbits = n_total - sum(t.stop - t.start for t in todo)
        n_todo = len(todo)
    else:  # planned lazily: one task per chunk in flight, not per chunk of the run
        todo = (
            ChunkTask(sj, chunk, start, stop, partition, h, packed.get(partition))
            for scene, partition, h in points
            for sj in (scene.to_json(),)
            for chunk, start, stop in plan_chunks(scene)
        )
        done_orbits, n_todo = 0, n_chunks

    def args(task: ChunkTask):
        ics = (
            (None, None)
            if table_ics is None
            else (table_ics[0][task.start : task.stop], table_ics[1][task.start : task.stop])
        )
        return (task.scene_json, task.chunk, task.start, task.stop, out_url, *ics, task.partition)

    t0 = time.perf_counter()
    bar = progress_bar(progress, n_total, done_orbits, run.name)

    reported = {}  # orbits of an unfinished chunk already shown (progress from inside chunks)

    def on_done(task, result):
        summary.add(result)
        bar.update(max(0, task.stop - task.start - reported.pop((task.partition, task.chunk), 0)))
        _check_stop()  # a stop asked for while the chunk ran, its exception lost on the way

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
                    key = (task.partition, task.chunk)
                    tell = (lambda k, key=key: on_progress(key, k)) if progress else None
                    on_done(task, run_one_chunk(*args(task), progress=tell, scene_hash=task.scene_hash, plan=task.plan))
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


def _run_pool(workers, todo, args, on_done, on_progress=None):
    ctx = mp.get_context("spawn")  # no fork of a process holding LLVM/JIT state
    pool = ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=die_with_parent, initargs=(os.getpid(),)
    )
    manager = None
    if on_progress is not None:
        manager = SyncManager(ctx=ctx)
        with _signals_held():
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

    def submit(t):
        with _signals_held():  # (the pool starts its worker processes in submit)
            return pool.submit(run_one_chunk, *args(t), progress=q, scene_hash=t.scene_hash, plan=t.plan)

    try:
        _drain(
            submit,
            wait_first,
            todo,
            2 * workers,
            on_done,
            lambda fs: [f.cancel() for f in fs],
        )
    except BaseException:  # an error or an interrupt: the chunks in flight are not waited for (their parts are
        _stop_workers(pool)  # temporaries until complete; --resume removes them and redoes those chunks)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        if manager is not None:
            manager.shutdown()


_HELD = {"depth": 0, "pending": []}  # sections that start a worker process, and the signals that came meanwhile
_STOP: list[int] = []  # signals that asked the run in progress to stop (:func:`request_stop`)


def request_stop(signum: int) -> None:
    """request_stop(signum): the run in progress stops after the chunk it is in, whatever happens to the
    exception the signal's handler raises. For a handler that stops the run (the CLI's): an exception raised in a
    signal handler is lost when the signal lands while Python runs a finaliser or a library's callback that
    swallows it; the run then checks this request after every finished chunk (``KeyboardInterrupt``). ``signum``
    is the number of a named signal of this platform (an int, e.g. ``signal.SIGTERM``: :class:`signal.Signals`).

    Examples
    --------
    >>> import signal
    >>> request_stop(signal.SIGTERM)
    >>> try:
    ...     _check_stop()
    ... except KeyboardInterrupt as stop:
    ...     print("stopped by", stop)
    stopped by SIGTERM
    >>> clear_stop()
    >>> _check_stop()      # nothing requested any more: the run goes on
    """
    if isinstance(signum, bool) or not isinstance(signum, int):
        raise ConfigError(f"signum must be a signal number (an int), got {signum!r}")
    try:
        signal.Signals(signum)
    except ValueError:
        raise ConfigError(f"signum = {signum} is the number of no named signal of this platform") from None
    _STOP.append(int(signum))


def clear_stop() -> None:
    """clear_stop(): forget the stop requests of an earlier command in this process (it takes no argument).

    Examples
    --------
    >>> import signal
    >>> request_stop(signal.SIGINT); request_stop(signal.SIGTERM)
    >>> clear_stop()
    >>> _check_stop()      # both forgotten
    """
    _STOP.clear()


def _check_stop() -> None:
    if _STOP:
        raise KeyboardInterrupt(signal.Signals(_STOP[0]).name)


def defer_signal(signum: int) -> bool:
    """defer_signal(signum) -> True while a worker process is being started: the signal is kept and raised again
    when the start is complete (:func:`_signals_held`). For a signal handler that stops the run (the CLI's): a
    start cut halfway leaves the new process reading a half-written pipe, an EOFError traceback on stderr."""
    if _HELD["depth"]:
        _HELD["pending"].append(signum)
        return True
    return False


@contextlib.contextmanager
def _signals_held():
    """The section in which the main thread starts a worker process; signals deferred meanwhile
    (:func:`defer_signal`) are raised again at its end."""
    _HELD["depth"] += 1
    try:
        yield
    finally:
        _HELD["depth"] -= 1
        if not _HELD["depth"] and _HELD["pending"]:
            signum = _HELD["pending"][0]
            _HELD["pending"].clear()
            signal.raise_signal(signum)


def _stop_workers(pool) -> None:
    """Terminate the pool's worker processes now (ProcessPoolExecutor.terminate_workers where it exists)."""
    stop = getattr(pool, "terminate_workers", None)
    if stop is not None:
        stop()
        return
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            proc.terminate()
        except (OSError, ValueError):  # gone already
            pass


def _run_dask(client, todo, args, on_done, name):
    from distributed import wait  # deferred: distributed loads on first use

    window = max(4, 2 * sum(client.nthreads().values()))
    tag = uuid.uuid4().hex[:8]

    def submit(task):
        key = f"hhscatter-{name}-{task.partition.replace('/', ',') + '-' if task.partition else ''}{task.chunk}-{tag}"
        return client.submit(
            run_one_chunk, *args(task), key=key, pure=False, retries=0, scene_hash=task.scene_hash, plan=task.plan
        )

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
                    "part files are intact: start workers and rerun with --resume"
                )

    _drain(submit, wait_first, todo, window, on_done, lambda fs: client.cancel(fs))
