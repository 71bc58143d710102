"""The output location of a run, checked and prepared before any work: empty, overwritten or resumed (the same
scene, no part outside the plan), locked for one writer."""

from __future__ import annotations

import json
import os
import shutil

from hhscatter._version import ENGINE_REVISION
from hhscatter.data.schema import TABLES
from hhscatter.data.store import LOCK_FILE, TMP_MARK, LockedError, Store
from hhscatter.errors import ConfigError, OutputError
from hhscatter.run.plan import SCENE_FILE, manifest_of, part_rel, points_of, tables_of
from hhscatter.scene.grid import Grid


def _diff(old: dict, new: dict) -> str:
    keys = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k) and k not in ("name", "batch_size"))
    return ", ".join(f"{k}: {old.get(k)!r} → {new.get(k)!r}" for k in keys[:6])


def _extra_parts(store, manifest) -> list[str]:
    """Part files under the table folders that the manifest does not plan (duplicates, junk, other runs)."""
    planned = {
        part_rel(name, p["partition"], c)
        for name in manifest["tables"]
        for p in manifest["points"]
        for c in range(-(-p["n"] // p["chunk_size"]))
    }
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
    if isinstance(out, (str, bytes)) and not str(out).strip():
        raise ConfigError(f"out must name a directory (or a URL), got {out!r}; the working directory is '.'")
    try:
        store = Store(out)
    except ValueError as exc:
        raise OutputError(str(exc)) from None
    if store.exists() and not store.is_dir():
        raise OutputError(f"out: {store.display()} exists and is not a directory")
    if points is None:
        points = [(sc, part, sc.result_hash()) for sc, part in points_of(run)]
    created = not store.exists()
    had_note = not created and store.exists(LOCK_FILE)
    lock = None
    try:
        try:
            lock = store.lock()
        except LockedError as exc:
            raise OutputError(f"out: {exc}; one writer per run directory: wait for it or use another --out") from None
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
        doc = {"scene": json.loads(run.to_json()), "scene_hash": run.result_hash(), "engine_revision": ENGINE_REVISION}

        if isinstance(run, Grid):
            doc["grid"] = {"energy": list(run.energies), "gamma": list(run.gammas)}
            doc["points"] = [{"partition": part, "scene_hash": h} for _, part, h in points]
        doc["manifest"] = manifest_of(points, tables_of(points[0][0]))
        try:
            store.write_json(SCENE_FILE, doc)
        except OSError as exc:
            raise OutputError(
                f"out: cannot write {store.display(SCENE_FILE)} ({exc.strerror or exc}); nothing was computed"
            ) from None
    except BaseException:
        if lock is not None and created:  # never a directory another writer made or holds
            shutil.rmtree(store.root, ignore_errors=True)
        elif lock is not None and not had_note:  # a refused folder keeps nothing of ours, not even the pid note
            try:
                store.remove(LOCK_FILE)
            except OSError:
                pass
        Store.unlock(lock)
        raise
    return store, lock, points


def _check_and_clear(run, store, points, *, overwrite, resume):
    """The emptiness / same-scene checks of prepare_output, under the lock; --overwrite clears the old run.
    --resume continues a run: without scene.json, a folder holding anything but a run's table folders is refused."""
    entries = [e for e in store.listdir() if e != LOCK_FILE]
    if not entries:
        return
    if overwrite:
        _remove_run(store, entries)
        return
    if not resume:
        raise OutputError(
            f"out: {store.display()} is not empty; pass --overwrite to replace it or --resume to continue it"
        )
    if not store.exists(SCENE_FILE):  # a run whose manifest is gone is verified part by part; anything else is not ours
        theirs = [e for e in entries if e not in TABLES and not _ours(e)]
        if theirs:
            raise OutputError(
                f"cannot resume into {store.display()}: it holds no hhscatter run (no {SCENE_FILE}: its manifest) "
                f"but {len(theirs)} entr{'y' if len(theirs) == 1 else 'ies'} (first: {theirs[0]}); --resume "
                "continues a run: use another --out, or empty it yourself"
            )
    else:
        old = json.loads(store.read_text(SCENE_FILE))
        if old.get("scene_hash") != run.result_hash():
            what = _diff(old.get("scene", {}), json.loads(run.to_json()))
            made = old.get("engine_revision", 1)  # a run from before the revision was recorded: revision 1
            if not what and made != ENGINE_REVISION:
                raise OutputError(
                    f"cannot resume into {store.display()}: its run was made by engine revision {made} (this "
                    f"engine: {ENGINE_REVISION}), whose tables may differ; use --overwrite or another --out"
                )
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


def _ours(rel: str) -> bool:
    """A file hhscatter leaves in a run directory outside its manifest: the writer's pid note, a temporary of a
    killed writer, a write probe."""
    base = rel.rsplit("/", 1)[-1]
    return rel == LOCK_FILE or (base.startswith(".") and TMP_MARK in base) or rel.startswith(".write-test-")


def _remove_run(store, entries) -> None:
    """--overwrite: remove exactly the files the old run's manifest lists (and the temporaries of killed writers),
    then the table folders left empty. A folder holding anything else (a file hhscatter did not write, a run
    without manifest) is refused before anything is removed: OutputError naming the first foreign entry."""
    where = store.display()
    if not store.exists(SCENE_FILE):
        raise OutputError(
            f"--overwrite: {where} holds no hhscatter run (no {SCENE_FILE}: its manifest) but "
            f"{len(entries)} entr{'y' if len(entries) == 1 else 'ies'} (first: {entries[0]}); "
            "--overwrite removes only what a run's manifest lists: empty it yourself or use another --out"
        )
    try:
        man = json.loads(store.read_text(SCENE_FILE))["manifest"]
        planned = {
            part_rel(name, p["partition"], c)
            for name in man["tables"]
            for p in man["points"]
            for c in range(-(-int(p["n"]) // int(p["chunk_size"])))
        }
    except (ValueError, KeyError, TypeError) as exc:
        raise OutputError(
            f"--overwrite: {store.display(SCENE_FILE)} holds no readable run manifest ({exc!r}); "
            "--overwrite removes only what a run's manifest lists: empty the folder yourself or use "
            "another --out"
        ) from None
    foreign = [e for e in entries if e not in (*TABLES, SCENE_FILE) and not _ours(e)]
    foreign += [
        f"{t}/{f}"
        for t in TABLES
        if store.is_dir(t)
        for f in store.files(t)
        if f"{t}/{f}" not in planned and not _ours(f"{t}/{f}")
    ]
    if foreign:
        raise OutputError(
            f"--overwrite: {where} holds {len(foreign)} entr{'y' if len(foreign) == 1 else 'ies'} its "
            f"run's manifest does not list (first: {store.display(foreign[0])}); hhscatter removes "
            "only what it wrote: move them away, or use another --out. Nothing was removed"
        )
    for t in TABLES:
        for f in store.files(t):
            store.remove(f"{t}/{f}")
        subs = {f.rsplit("/", k)[0] for f in planned if f.startswith(f"{t}/") for k in range(1, f.count("/"))}
        for sub in sorted(subs, key=lambda d: d.count("/"), reverse=True):  # point folders, deepest first
            if store.is_dir(sub) and not store.listdir(sub):
                store.remove(sub)
        if store.is_dir(t) and not store.listdir(t):
            store.remove(t)
    for e in entries:
        if _ours(e):
            store.remove(e)
    store.remove(SCENE_FILE)


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


def discard_failed_start(store, *, remove_root: bool) -> bool:
    """discard_failed_start(store, remove_root) -> True if the run at ``store`` was removed: a new run that ended
    (an error, an interrupt) before any part file was written keeps nothing (its scene.json, lock note, write
    probe, temporaries and empty table folders; the folder itself when ``remove_root``, i.e. the run made it).
    A run with a written part is kept, for ``--resume``."""
    try:
        for name in TABLES:
            if any(not _ours(f"{name}/{f}") for f in store.files(name)):
                return False
        for e in store.listdir():
            if e in TABLES or e == SCENE_FILE or _ours(e):
                store.remove(e)
        if remove_root and not store.listdir():
            store.remove("")
    except OSError:
        return False
    return True
