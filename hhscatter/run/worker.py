"""The worker side of a run: integrate one (point, chunk) and write its part files; check a finished chunk;
workers that die with the process that started them."""

from __future__ import annotations

import functools
import hashlib
import json
import os
import pickle
import signal
import sys
import threading
import time

import numpy as np

from hhscatter._version import ENGINE_REVISION
from hhscatter.data.schema import add_point_columns, provenance, to_arrow
from hhscatter.data.store import Store
from hhscatter.data.verify import read_meta, verify_part
from hhscatter.data.write import write_part
from hhscatter.errors import RunIntegrityError
from hhscatter.integrate.engine import run_chunk
from hhscatter.integrate.plan import plan_of
from hhscatter.model.landscape import unbounded_derivation
from hhscatter.run.plan import RunSummary, _decode, part_rel, tables_of
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene, scene_from_dict


def _chunk_ics(scene, start, stop, table_ics):
    if table_ics is not None:
        states, ids = table_ics
        return states[start:stop], ids[start:stop]

    return region_ics(scene, start, stop), np.arange(start, stop, dtype=np.int64)


def pack_point(scene: Scene) -> bytes:
    """pack_point(scene) -> bytes: the scene and its engine plan (:func:`hhscatter.integrate.plan.plan_of`), built
    once and pickled together, as a run hands them to every chunk of the point (its worker processes and Dask's
    unpickle them as they are: no scene is rebuilt and no system derived again there).

    Example: ``pickle.loads(pack_point(Scene(energy=0.2, n=10)))[1].scheduler`` is ``'stream'``.
    """
    return pickle.dumps((scene, plan_of(scene)), protocol=pickle.HIGHEST_PROTOCOL)


@functools.lru_cache(maxsize=8)
def _unpack_point(packed: bytes):
    """(scene, plan) of :func:`pack_point`'s bytes: unpickled once per worker process and point."""
    return pickle.loads(packed)


@functools.lru_cache(maxsize=8)
def _scene_and_plan(scene_json: str):
    """(scene, its engine plan) of a point's scene JSON, for a caller that hands no :func:`pack_point` bytes."""
    with unbounded_derivation():  # the client accepted this scene: its system is rebuilt here whatever it takes
        scene = scene_from_dict(_decode(json.loads(scene_json)))
    return scene, plan_of(scene)


def run_one_chunk(
    scene_json: str,
    chunk: int,
    start: int,
    stop: int,
    out,
    ics=None,
    ids=None,
    partition="",
    progress=None,
    scene_hash=None,
    plan=None,
):
    """run_one_chunk(scene_json, chunk, start, stop, out, ics=None, ids=None, partition='', progress=None,
    scene_hash=None, plan=None) -> RunSummary.

    Worker entry (local pool or Dask): integrate orbits start..stop−1 of the
    scene, write the chunk's part files under ``out`` (path or URL) and
    return the chunk's counts. An OSError while writing is re-raised naming
    the file. ``progress``: a callable f(k), or a queue that gets (chunk, k)
    (another process's), told as orbits of the chunk start. ``scene_hash``: the scene's result hash as
    the client computed it once per run (default: computed here, which re-reads an IC table). ``plan``: the
    point's :func:`pack_point` bytes, made once per run (default: the scene rebuilt from ``scene_json`` and its
    plan built here, once per process).
    """

    scene, plan = _unpack_point(plan) if plan is not None else _scene_and_plan(scene_json)
    store = Store(out)
    if ics is None:
        ics, ids = _chunk_ics(scene, start, stop, None)
    if progress is not None and not callable(progress):
        queue, key = progress, (partition, chunk)
        progress = lambda k: queue.put((key, k))  # noqa: E731 - a queue proxy of the parent's Manager
    t0 = time.perf_counter()
    res = run_chunk(plan, ics, ids, progress=progress)
    elapsed = time.perf_counter() - t0
    meta = {
        "scene": footer_scene(json.loads(scene_json)),
        "scene_hash": scene_hash or scene.result_hash(),
        "chunk": chunk,
        "orbits": [start, stop],
        **provenance(),
    }
    key = f"{partition}/{chunk}" if partition else str(chunk)
    if res.event_failures:  # heyoka ignored an event in some step: counted, and the orbits hit were redone
        meta["event_failures"] = {"count": res.event_failures, "redone": [int(k) for k in res.redone]}
    if res.tangent_beyond:  # orbits whose log-stretch passed MAX_LOG_STRETCH (the tangent dynamics), counted
        meta["tangent_beyond"] = res.tangent_beyond
    if scene.system is not None:  # which system, as text (Hénon–Heiles with linear drag: ω, λ in the scene)
        meta["system"] = scene.model.provenance()
    rows = res.tables()
    # lifetimes last: its presence marks a complete chunk
    for name in reversed(tables_of(scene)):
        table = to_arrow(name, rows[name])
        if partition and "=" not in partition:  # a grid point's files name their point (hhscatter.data.schema)
            table = add_point_columns(name, table, scene)
        rel = part_rel(name, partition, chunk)
        try:
            # no directory fsync per part: a rename a power cut undoes only makes resume redo the chunk
            write_part(rel, table, {**meta, "table": name, "rows": table.num_rows}, store=store, sync_dir=False)
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
        event_failures={key: {"failures": res.event_failures, "orbits_redone": len(res.redone)}}
        if res.event_failures
        else {},
        tangent_beyond=res.tangent_beyond,
    )


#: a part's footer names at most this many snapshot times; a longer list is named by its count, ends and SHA-256
#: (scene.json holds every time once): 10⁵ times would add ≈ 2 MB to every part
FOOTER_TIMES_MAX = 100


def footer_scene(d: dict) -> dict:
    """footer_scene(scene dict) -> the scene as a part's metadata records it: a list of snapshot times longer than
    :data:`FOOTER_TIMES_MAX` as ``{"count", "first", "last", "sha256"}`` (of the list's JSON), the rest unchanged.

    Example: ``footer_scene({"snapshots": [0.0, 1.0]})`` is ``{"snapshots": [0.0, 1.0]}``.
    """
    times = d.get("snapshots")
    if not isinstance(times, list) or len(times) <= FOOTER_TIMES_MAX:
        return d
    digest = hashlib.sha256(json.dumps(times).encode()).hexdigest()
    return {**d, "snapshots": {"count": len(times), "first": times[0], "last": times[-1], "sha256": digest}}


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
            made = meta.get("engine_revision", 1)  # a part from before the revision was recorded: revision 1
            why = (
                f"by engine revision {made} (this engine: {ENGINE_REVISION})"
                if made != ENGINE_REVISION
                else "by a different scene"
            )
            raise RunIntegrityError(
                f"cannot resume: {store.display(rel)} was made {why} (hash "
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


def kept_tangent_beyond(out, chunk: int, partition: str = "") -> int:
    """kept_tangent_beyond(out, chunk, partition='') -> int: the orbits of a kept (complete) chunk whose log-stretch
    passed :data:`~hhscatter.integrate.events.MAX_LOG_STRETCH`, as its lifetimes part's metadata records them (0 when
    it records none), so that a resumed run's total counts the chunks it keeps as well as those it runs."""
    store = Store(out)
    meta = read_meta(store.path(part_rel("lifetimes", partition, chunk)), filesystem=store.filesystem)
    return int(meta.get("tangent_beyond", 0))


def die_with_parent(parent_pid: int) -> None:
    """die_with_parent(parent_pid) -> None: make this (worker) process die when its parent does.

    Linux: ``prctl(PR_SET_PDEATHSIG, SIGKILL)``, which the kernel applies however the parent ends
    (SIGTERM, SIGINT, kill -9), so no worker keeps computing and writing parts for a run that is gone.
    Elsewhere: a daemon thread that polls the parent every second. The pool's and the progress
    manager's initializer. It also ignores SIGINT (the parent answers Ctrl-C and stops its workers).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
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


def default_workers() -> int:
    """default_workers() -> the number of CPUs this process may use (its affinity mask), at least 1."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)
