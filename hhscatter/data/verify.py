"""A run's part files verified against its manifest (``scene.json``): the metadata and checksums of one part, the
run's plan and completion, the verified Arrow dataset of one table that :mod:`hhscatter.data.read` reads, and what a
run holds (:func:`describe_run`).

A run read through :func:`verified_dataset` is read as exactly the part files its manifest plans and that are
finished, each checked against the plan (scene hash, chunk, orbit range, row count) with its data pages'
checksums verified as they are read. A missing table or part, a part outside the plan, of another scene or damaged
raise :class:`~hhscatter.errors.RunIntegrityError`; an unfinished run raises
:class:`~hhscatter.errors.IncompleteRunError` unless ``allow_partial=True``.
"""

from __future__ import annotations

import json
import warnings

import numpy as np

from hhscatter.data.schema import (
    META_KEY,
    OPTIONAL_COLUMNS,
    POINT_COLUMNS,
    TABLES,
    legacy_point,
    part_name,
    schema_of,
)
from hhscatter.data.store import Store
from hhscatter.errors import IncompleteRunError, RunIntegrityError

__all__ = ["describe_run", "read_meta", "run_manifest", "run_status", "scan_checked", "verified_dataset", "verify_part"]


def read_meta(path, filesystem=None) -> dict:
    """read_meta(path, filesystem=None) -> the ``hhscatter`` metadata dict of one part file."""
    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    md = pq.read_schema(path, filesystem=filesystem).metadata or {}
    if META_KEY not in md:
        raise ValueError(f"{path} is not an hhscatter table (no '{META_KEY.decode()}' metadata)")
    return json.loads(md[META_KEY])


def verify_part(source, expect_rows=None) -> dict:
    """verify_part(source, expect_rows=None) -> metadata dict, or raise ValueError/OSError.

    Reads the whole file (``source``: path or open pyarrow file) with page
    checksum verification: a truncated file, a damaged footer or data page, a
    row count different from the metadata's (or from ``expect_rows``) raise.
    """
    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    pf = pq.ParquetFile(source, page_checksum_verification=True)
    md = pf.schema_arrow.metadata or {}
    if META_KEY not in md:
        raise ValueError("not an hhscatter table")
    meta = json.loads(md[META_KEY])
    table = pf.read()
    if table.num_rows != meta.get("rows") or (expect_rows is not None and table.num_rows != expect_rows):
        raise ValueError(f"row count {table.num_rows} differs from the metadata's {meta.get('rows')}")
    return meta


def run_manifest(run_dir) -> dict | None:
    """run_manifest(run_dir) -> the run's plan from OUT/scene.json (hhscatter.run.plan.manifest_of), or None.

    None for a directory without scene.json or a run written before manifests (read as before, by
    listing its part files).
    """
    store = Store(run_dir)
    if not store.exists("scene.json"):
        return None
    return json.loads(store.read_text("scene.json")).get("manifest")


def _without_manifest(store) -> RunIntegrityError:
    """The error for a run directory whose scene.json (its manifest) is gone: its parts cannot be told complete."""
    hashes = set()
    for f in store.files("lifetimes")[:1]:
        try:
            hashes.add(str(read_meta(store.path("lifetimes", f), filesystem=store.filesystem).get("scene_hash"))[:12])
        except (OSError, ValueError):
            pass
    said = f" (its parts say they belong to scene {hashes.pop()}…)" if hashes else ""
    return RunIntegrityError(
        f"the run at {store.display()} has no scene.json, its manifest{said}: without it "
        "nobody can tell whether the run is complete; rerun the same `hhscatter simulate` "
        "with --resume (it verifies the parts and writes the manifest again) or --overwrite"
    )


def run_status(run_dir) -> dict:
    """run_status(run_dir) -> {'complete', 'chunks', 'chunks_done', 'orbits', 'orbits_done', 'scene_hash'}.

    From the manifest and the presence of the ``lifetimes`` parts (written last in every chunk); cheap
    (no file is opened). A run written before manifests (a scene.json without one) counts as complete if it has
    lifetimes parts; a run directory without scene.json raises :class:`RunIntegrityError` (nothing says which
    parts it should have).
    """
    store = Store(run_dir)
    if not store.exists("scene.json"):
        if store.exists("lifetimes"):
            raise _without_manifest(store)
        raise FileNotFoundError(f"{store.display()} holds no run (no scene.json)")
    doc = json.loads(store.read_text("scene.json"))
    man = doc.get("manifest")
    if man is None:
        n = len(store.files("lifetimes"))
        return {
            "complete": n > 0,
            "chunks": n,
            "chunks_done": n,
            "orbits": None,
            "orbits_done": None,
            "scene_hash": doc.get("scene_hash"),
        }
    have = set(store.files("lifetimes"))
    chunks = done = orbits = orbits_done = 0
    for p in man["points"]:
        for c in range(-(-p["n"] // p["chunk_size"])):
            k = min(p["chunk_size"], p["n"] - c * p["chunk_size"])
            chunks, orbits = chunks + 1, orbits + k
            if "/".join(x for x in (p["partition"], part_name(c)) if x) in have:
                done, orbits_done = done + 1, orbits_done + k
    return {
        "complete": done == chunks,
        "chunks": chunks,
        "chunks_done": done,
        "orbits": orbits,
        "orbits_done": orbits_done,
        "scene_hash": doc.get("scene_hash"),
    }


def _planned_files(store, man: dict, name: str, allow_partial: bool):
    """The part files of table ``name`` that the manifest plans and the run has finished, as
    [(file relative to the table folder, point dict, chunk)]; RunIntegrityError on anything else."""
    run = store.display()
    if name not in man["tables"]:
        raise FileNotFoundError(
            f"no {name} table: the run at {run} does not record it (its tables: {', '.join(man['tables'])})"
        )
    if not store.is_dir(name):
        raise RunIntegrityError(
            f"the {name} table of the run at {run} is missing ({store.display(name)} "
            "does not exist); the run is damaged: simulate it again with --overwrite"
        )
    present = {f for f in store.files(name) if not f.rsplit("/", 1)[-1].startswith(".")}
    finished = present if name == "lifetimes" else {f for f in store.files("lifetimes")}
    planned, missing_chunks, missing_orbits, chunks, orbits = [], 0, 0, 0, 0
    expected = set()
    for p in man["points"]:
        for c in range(-(-p["n"] // p["chunk_size"])):
            rel = "/".join(x for x in (p["partition"], part_name(c)) if x)
            expected.add(rel)
            k = min(p["chunk_size"], p["n"] - c * p["chunk_size"])
            chunks, orbits = chunks + 1, orbits + k
            if rel not in finished:
                missing_chunks, missing_orbits = missing_chunks + 1, missing_orbits + k
                continue
            if rel not in present:
                raise RunIntegrityError(
                    f"{store.display(name + '/' + rel)} is missing, but its chunk is "
                    "finished; the run is damaged: simulate it again with --overwrite"
                )
            planned.append((rel, p, c))
    extra = sorted(present - expected)
    if extra:
        raise RunIntegrityError(
            f"{len(extra)} file(s) in {store.display(name)} are not in the run's chunk plan "
            f"(first: {extra[0]}); remove them or simulate the run again with --overwrite"
        )
    if missing_chunks:
        what = (
            f"the run at {run} is incomplete: {missing_chunks} of {chunks} chunk(s) "
            f"({missing_orbits} of {orbits} orbits) are not finished"
        )
        if allow_partial and (pid := store.writer()) is not None:
            # its finished chunks change from one read to the next: two tables read apart would not match
            raise IncompleteRunError(
                f"{what}, and it is being written now (pid {pid}): reading its finished chunks "
                "(allow_partial=True) gives each table as of another moment; wait until the "
                "writer ends (or stop it), then read"
            )
        if not allow_partial:
            raise IncompleteRunError(
                f"{what}; finish it with `hhscatter simulate --out {run} --resume`, or read "
                "the finished chunks with allow_partial=True"
            )

        warnings.warn(
            f"{what}; reading the {orbits - missing_orbits} orbits of the finished chunks (allow_partial=True)",
            stacklevel=4,
        )
    return planned


def _check_fragment(store, name, frag, point, chunk):
    """A part's own metadata must say it is this chunk of this scene, with as many rows as it holds."""
    md = frag.metadata
    kv = md.metadata or {}
    where = frag.path
    if META_KEY not in kv:
        raise RunIntegrityError(f"{where} is not an hhscatter table (no '{META_KEY.decode()}' metadata)")
    meta = json.loads(kv[META_KEY])
    if meta.get("scene_hash") != point["scene_hash"]:
        raise RunIntegrityError(
            f"{where} was made by another scene (hash {str(meta.get('scene_hash'))[:12]}…, "
            f"this run {point['scene_hash'][:12]}…); simulate the run again with --overwrite"
        )
    c, k = point["chunk_size"], chunk * point["chunk_size"]
    want = [k, min(k + c, point["n"])]
    if (
        meta.get("chunk") != chunk
        or meta.get("orbits") != want
        or meta.get("table") not in (None, name)
        or meta.get("rows") != md.num_rows
    ):
        raise RunIntegrityError(
            f"{where} does not hold chunk {chunk} (orbits {want}) of the {name} table "
            f"(its metadata: chunk {meta.get('chunk')}, orbits {meta.get('orbits')}, "
            f"rows {meta.get('rows')} of {md.num_rows})"
        )


def _optional_columns(name, path, fs) -> list:
    """The :data:`~hhscatter.data.schema.OPTIONAL_COLUMNS` of table ``name`` that its part file ``path`` holds (a
    run's parts all have the same columns: they are of one scene)."""
    if not OPTIONAL_COLUMNS.get(name):
        return []
    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    try:
        names = pq.read_schema(path, filesystem=fs).names
    except (OSError, ValueError):  # not readable: the dataset's own checks report it
        return []
    return [c for c in OPTIONAL_COLUMNS[name] if c in names]


def verified_dataset(run_dir, name: str, *, one_by_one: bool = False, allow_partial: bool = False):
    """verified_dataset(run_dir, name) -> pyarrow.dataset of one table (a plain run or a grid run, either layout).

    A run with a manifest (scene.json, hhscatter.run.plan.manifest_of) is read as exactly its planned and
    finished part files: each part's metadata is checked against the plan (scene hash, chunk, orbit range,
    row count; :func:`_check_fragment`, one footer per part) and every data page's checksum is verified as
    it is read. A missing table or part, a part not in the plan or of another scene raise
    :class:`RunIntegrityError`; unfinished chunks :class:`IncompleteRunError` unless ``allow_partial``
    (then only the finished chunks are read, in every table alike, with a warning saying how much is
    missing). ``one_by_one=True`` yields one single-file dataset per part instead: pyarrow
    keeps each scanned file's footer while its dataset lives, so a streaming
    scan over many thousands of parts is done file by file.
    """
    import pyarrow as pa  # deferred: pyarrow loads on first use
    import pyarrow.dataset as ds  # deferred: pyarrow loads on first use
    import pyarrow.fs as pafs  # deferred: pyarrow loads on first use

    store = Store(run_dir)
    man = run_manifest(run_dir)
    checks = None
    if man is not None:
        rel = name
        planned = _planned_files(store, man, name, allow_partial)
        files = [f for f, _, _ in planned]
        checks = [(p, c) for _, p, c in planned]
        if not files:
            raise IncompleteRunError(f"no {name} table: no chunk of the run at {store.display()} is finished")
    elif not store.exists("scene.json"):
        raise (
            _without_manifest(store)
            if store.exists(name) or store.exists("lifetimes")
            else FileNotFoundError(f"no {name} table: {store.display()} holds no run (no scene.json)")
        )
    else:
        rel = name if store.is_dir(name) or store.exists("scene.json") else ""
        if not store.exists(rel):
            raise FileNotFoundError(f"no {name} table at {store.display(rel)}")
        files = [f for f in store.files(rel) if f.rsplit("/", 1)[-1].startswith("part-") and f.endswith(".parquet")]
        if not files:
            where = store.display(rel) if rel else f"{store.display()} (no {name}/ folder)"
            raise FileNotFoundError(f"no {name} table: no part files in {where}")
    grid = any("/" in f for f in files)
    paths = [store.path(rel, f) for f in files]
    fs = store.filesystem or pafs.LocalFileSystem()
    schema = schema_of(name, grid, _optional_columns(name, paths[0], fs))
    # every data page's CRC (written by write_part) is verified as it is read
    fmt = ds.ParquetFileFormat(
        default_fragment_scan_options=ds.ParquetFragmentScanOptions(page_checksum_verification=True)
    )
    legacy = [legacy_point(f) for f in files]
    if any(p is not None for p in legacy):
        # old hive layout: the point is in the folder names only (and the key 'gamma' clashes with the
        # lifetimes column, 'energy' with the sections/snapshots column); give each file its point as a
        # partition expression on the new column names, which pyarrow materialises as constant columns
        if None in legacy:
            raise ValueError(f"{store.display(rel)} mixes part files of two layouts")
        cols = dict(POINT_COLUMNS[name])
        if name == "lifetimes":
            cols["gamma"] = "gamma"
        inv = {v: k for k, v in cols.items()}
        exprs = [(ds.field(inv["energy"]) == e) & (ds.field(inv["gamma"]) == g) for e, g in legacy]

        def make(ps, es):
            return ds.FileSystemDataset.from_paths(ps, schema=schema, format=fmt, filesystem=fs, partitions=es)
    else:
        exprs = [ds.scalar(True)] * len(paths)

        def make(ps, es):
            return ds.dataset(ps, schema=schema, format=fmt, filesystem=store.filesystem)

    def checked(ps, es, which):
        try:
            dset = make(ps, es)
            if checks is not None:
                for frag, (point, chunk) in zip(dset.get_fragments(), which):
                    _check_fragment(store, name, frag, point, chunk)
        except pa.ArrowInvalid as exc:  # a file under a part's name that is no Parquet file
            raise RunIntegrityError(
                f"a part of the {name} table of the run at {store.display()} is not a "
                f"readable Parquet file ({exc}); the run is damaged: rerun it with --resume "
                "(damaged chunks are redone) or --overwrite"
            ) from None
        return dset

    if one_by_one:
        return (checked([p], [e], [checks[i]] if checks else None) for i, (p, e) in enumerate(zip(paths, exprs)))
    return checked(paths, exprs, checks)


def scan_checked(dset, run_dir, name, scan):
    """scan(dset) with a damaged data page (page checksum mismatch) reported as RunIntegrityError naming the
    part file (found by verifying the dataset's files one by one: only on this error path)."""
    try:
        return scan(dset)
    except OSError as exc:
        if "checksum" not in str(exc).lower():
            raise
        bad = "?"
        for path in dset.files:
            try:
                verify_part(dset.filesystem.open_input_file(path))
            except (OSError, ValueError):
                bad = path
                break
        raise RunIntegrityError(
            f"{bad} is damaged: a data page fails its checksum ({exc}); delete it and "
            f"rerun `hhscatter simulate --out {run_dir} --resume`"
        ) from None


def _describe_parts(store, man):
    """describe_run of a local run with a manifest, from its part files one by one with ``pyarrow.parquet``
    (the same checks as :func:`verified_dataset`: the plan, each part's metadata, the checksums of the pages read):
    ``pyarrow.dataset`` and the pandas it imports cost ~0.5 s, which every ``simulate`` paid for its closing
    lines. None for a part that holds more than one grid point (then :func:`verified_dataset` counts)."""
    import types  # deferred: only this path needs it

    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    rows, points = {}, {}
    for name in man["tables"]:
        rows[name] = 0
        for rel, point, chunk in _planned_files(store, man, name, False):
            path = store.path(name, rel)
            try:
                pf = pq.ParquetFile(path, page_checksum_verification=True)
            except (OSError, ValueError) as exc:  # (pyarrow's ArrowInvalid is a ValueError)
                raise RunIntegrityError(
                    f"{path} is not a readable Parquet file ({exc}); the run is damaged: rerun "
                    "it with --resume (damaged chunks are redone) or --overwrite"
                ) from None
            _check_fragment(store, name, types.SimpleNamespace(metadata=pf.metadata, path=path), point, chunk)
            rows[name] += pf.metadata.num_rows
            if name != "lifetimes":
                continue
            t = pf.read(columns=[k for k in ("energy", "gamma", "outcome") if k in pf.schema_arrow.names])
            if "energy" in t.column_names:  # a grid point's part
                keys = set(zip(t.column("energy").to_pylist(), t.column("gamma").to_pylist()))
                if len(keys) != 1:
                    return None
                key = keys.pop()
            else:  # a plain run: its one point is the scene's
                meta = json.loads(pf.schema_arrow.metadata[META_KEY])["scene"]
                key = (meta.get("energy"), meta.get("gamma"))
            out = t.column("outcome").combine_chunks()
            ix = out.indices  # (Arrow's to_numpy imports pandas too: the codes straight from their buffer)
            # int8 as written; pyarrow before 17 reads a dictionary column's indices back as int32
            width = np.dtype(f"int{ix.type.bit_width}")
            codes = np.frombuffer(ix.buffers()[1], dtype=width, count=len(ix), offset=ix.offset * width.itemsize)
            counts = points.setdefault(key, {"escaped": 0, "settled": 0, "censored": 0, "stopped": 0})
            for o, c in zip(out.dictionary.to_pylist(), np.bincount(codes, minlength=len(out.dictionary))):
                if c:
                    counts[o] += int(c)
    return {
        "rows": rows,
        "points": [
            {"energy": k[0], "gamma": k[1], **v}
            for k, v in sorted(points.items(), key=lambda kv: [(x is None, x or 0.0) for x in kv[0]])
        ],
    }


def describe_run(run_dir) -> dict:
    """describe_run(run_dir) -> {'rows': {table: rows}, 'points': [{energy, gamma, escaped, settled, censored}]}.

    What a run directory holds, from the files themselves (so resumed chunks
    count too): the row count of each table present (from the Parquet
    footers) and the outcome counts per grid point (one entry for a plain run,
    whose ``energy`` is the scene's E0, None for runs from an IC table).
    """
    store = Store(run_dir)
    rows = {}
    man = run_manifest(run_dir)
    if man is not None and store.local and not any("=" in p["partition"] for p in man["points"]):
        light = _describe_parts(store, man)
        if light is not None:
            return light
    for name in TABLES:
        if (name in man["tables"]) if man is not None else store.is_dir(name):
            try:
                rows[name] = verified_dataset(run_dir, name).count_rows()
            except FileNotFoundError:
                continue
    if "lifetimes" not in rows:
        raise FileNotFoundError(f"no lifetimes table at {store.display('lifetimes')}")
    dset = verified_dataset(run_dir, "lifetimes")
    keys = [k for k in ("energy", "gamma") if k in dset.schema.names]
    table = dset.to_table(columns=[*keys, "outcome"])
    counts = table.group_by([*keys, "outcome"]).aggregate([([], "count_all")]).to_pylist()
    points = {}
    for r in counts:
        key = tuple(r[k] for k in keys)
        points.setdefault(key, {"escaped": 0, "settled": 0, "censored": 0, "stopped": 0})[r["outcome"]] = r["count_all"]
    if "energy" not in keys:  # a plain run: its one point is the scene's
        meta = read_meta(next(iter(dset.files)), filesystem=store.filesystem)["scene"]
        points = {(meta.get("energy"), meta.get("gamma")): c for c in points.values()}
    return {
        "rows": rows,
        "points": [
            {"energy": k[0], "gamma": k[1], **v}
            for k, v in sorted(points.items(), key=lambda kv: [(x is None, x or 0.0) for x in kv[0]])
        ],
    }
