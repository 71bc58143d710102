"""Read a run's tables, verified against its manifest (the contract: :mod:`hhscatter.data.schema`).

A run read by these functions is read as exactly the part files its manifest (``scene.json``) plans and that are
finished, each checked against the plan (scene hash, chunk, orbit range, row count) with its data pages'
checksums verified. A missing table or part, a part outside the plan, of another scene or damaged raise
:class:`~hhscatter.errors.RunIntegrityError` (exit status 2 in the CLI); an unfinished run raises
:class:`~hhscatter.errors.IncompleteRunError` unless ``allow_partial=True``, which reads the finished chunks of
every table alike and warns how much is missing. Runs of the legacy grid layout are read with the columns of
the current one.

A frame returned here carries what it was read from in ``DataFrame.attrs["hhscatter"]`` (:func:`run_identity`:
the run's scene and hash), where the analysis functions read E0, γ, t_max … (:mod:`hhscatter.data.params`).
:func:`read_lifetimes` of a list of runs keeps them apart (a ``run`` column: one point per run), refuses the
same run or scene twice, and pools them only when asked (``pool=True``, checked).
"""

from __future__ import annotations

import json
import re
import warnings
from typing import TYPE_CHECKING

import numpy as np

from hhscatter.data.params import FRAME_META
from hhscatter.data.store import Store
from hhscatter.data.verify import (  # noqa: F401 - the verification's public names are importable from here too
    describe_run,
    read_meta,
    run_manifest,
    run_status,
    scan_checked,
    verified_dataset,
    verify_part,
)
from hhscatter.errors import ConfigError
from hhscatter.outcomes import CENSORING_OUTCOMES

if TYPE_CHECKING:  # annotations only
    import pandas
    import pyarrow.dataset
from hhscatter.data.schema import (
    RunPath,
)


def _public_fields(dset) -> list[str]:
    """The columns a user may read or filter on: the table's fields (the storage's own are left out)."""
    return [f for f in dset.schema.names if not f.startswith("_")]


def _expression(filters):
    """``filters`` as a pyarrow expression: an expression as given, or the pandas/pyarrow list form
    ``[("energy", "==", 0.3), …]`` (a conjunction; a list of such lists, a disjunction); ConfigError otherwise."""
    import pyarrow.compute as pc  # deferred: pyarrow loads on first use

    if filters is None or isinstance(filters, pc.Expression):
        return filters
    if isinstance(filters, (list, tuple)) and filters:
        import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

        try:
            return pq.filters_to_expression(list(filters))
        except (TypeError, ValueError) as exc:
            raise ConfigError(
                f"filters {filters!r} is not a list of (column, op, value) triples (or a list of such lists): {exc}"
            ) from None
    raise ConfigError(
        "filters must be a pyarrow expression, e.g. pyarrow.dataset.field('energy') == 0.3, or the list form "
        f"[('energy', '==', 0.3)], got {type(filters).__name__} {str(filters)[:60]!r}"
    )


def _scan(dset, run_dir, name: str, columns, filters, scan):
    """``scan(dset, columns, expression)`` of a verified dataset, with the columns and the filter's fields checked
    against the table's (ConfigError naming the unknown one and the table's columns) and damaged pages reported
    (:func:`~hhscatter.data.verify.scan_checked`)."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    fields = _public_fields(dset)
    if columns is not None:
        if isinstance(columns, str) or not all(isinstance(c, str) for c in columns):
            raise ConfigError(f"columns must be a list of column names, got {columns!r}")
        unknown = [c for c in columns if c not in dset.schema.names]
        if unknown:
            raise ConfigError(
                f"columns {unknown} are not in the {name} table of {run_dir}; its columns: {', '.join(fields)}"
            )
        columns = list(columns)
    expr = _expression(filters)
    try:
        return scan_checked(dset, run_dir, name, lambda d: scan(d, columns, expr))
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError) as exc:
        text = str(exc)
        m = re.search(r"FieldRef\.Name\(([^)]*)\)", text)
        what = (
            f"the field {m.group(1)!r}, which is not a column"
            if m
            else f"what it cannot compare ({text.splitlines()[0]})"
        )
        raise ConfigError(
            f"filters {expr} names {what} of the {name} table of {run_dir}; its columns: {', '.join(fields)}"
        ) from None


def _nothing_matched(df, run_dir, name: str, filters) -> None:
    """Say so when a filter kept no row: a warning naming the filter and the run's grid values (a value that is
    not a grid point matches nothing), and ``attrs['hhscatter']['nothing_matched']``."""
    if filters is None or len(df):
        return
    scene = df.attrs.get(FRAME_META, {}).get("scene") or {}
    grid = "; ".join(
        f"{k} = {', '.join(f'{v:g}' for v in np.atleast_1d(scene[k]))}" for k in ("energy", "gamma") if k in scene
    )
    msg = f"nothing matched filters {_expression(filters)} in the {name} table of {run_dir}" + (
        f" (its points: {grid})" if grid else ""
    )
    df.attrs[FRAME_META] = {**df.attrs.get(FRAME_META, {}), "nothing_matched": msg}
    warnings.warn(msg, UserWarning, stacklevel=3)


def _read(run_dir, name: str, columns=None, filters=None, categorical: bool = False, allow_partial: bool = False):
    table = _scan(
        verified_dataset(run_dir, name, allow_partial=allow_partial),
        run_dir,
        name,
        columns,
        filters,
        lambda d, c, f: d.to_table(columns=c, filter=f),
    )
    df = table.to_pandas()
    if "outcome" in df.columns and not categorical:
        df["outcome"] = df["outcome"].astype(str)
    if "exit_channel" in df.columns:
        df["exit_channel"] = df["exit_channel"].astype("Int8")
    df.attrs[FRAME_META] = run_identity(run_dir)
    _nothing_matched(df, run_dir, name, filters)
    return df


#: scene keys that do not change the physics of an ensemble: runs that differ only in these may be pooled
POOLABLE_KEYS = ("seed", "n", "name", "batch_size", "chunk_size")


def _decode_scene(d: dict) -> dict:
    """A scene dict of scene.json with the JSON encoding of infinities ("inf", "-inf") undone."""
    d = dict(d)
    sec = d.get("sections")
    if isinstance(sec, dict):
        d["sections"] = {k: (float(v) if isinstance(v, str) and v.lstrip("-") == "inf" else v) for k, v in sec.items()}
    return d


def run_identity(run_dir) -> dict:
    """run_identity(run_dir) -> {'run', 'scene_hash', 'scene', 'point_hashes', 'grid'}: what a run directory is.

    From its ``scene.json`` (the scene or grid it was made from, with infinities decoded, its result hash and
    the result hash of each grid point), else from the metadata of its first lifetimes part (a run written
    before manifests). The readers leave this in ``DataFrame.attrs["hhscatter"]`` of what they return, so that
    the analysis functions read E0, γ, t_max, the section window … from the data instead of trusting a
    number typed again (:mod:`hhscatter.data.params`).
    """
    store = Store(run_dir)
    if store.exists("scene.json"):
        doc = json.loads(store.read_text("scene.json"))
        points = (
            [p["scene_hash"] for p in (doc.get("manifest") or {}).get("points", [])]
            or [p["scene_hash"] for p in doc.get("points", [])]
            or [doc.get("scene_hash")]
        )
        scene = doc.get("scene") or {}
    else:
        first = next((f for f in store.files("lifetimes") if f.endswith(".parquet")), None)
        if first is None:
            raise FileNotFoundError(f"no lifetimes table at {store.display('lifetimes')}")
        meta = read_meta(store.path("lifetimes", first), filesystem=store.filesystem)
        doc, scene = {"scene_hash": meta.get("scene_hash")}, meta.get("scene") or {}
        points = [doc["scene_hash"]]
    grid = any(isinstance(scene.get(k), list) for k in ("energy", "gamma"))
    return {
        "run": str(run_dir),
        "scene_hash": doc.get("scene_hash"),
        "scene": _decode_scene(scene),
        "point_hashes": [h for h in points if h],
        "grid": grid,
    }


def _distinct_runs(run_dirs) -> list[dict]:
    """The identities of a list of runs, refused (ValueError) if one run, or one grid point, comes twice."""
    ids, seen, where = [], {}, {}
    for r in run_dirs:
        root = Store(r).root
        if root in where:
            raise ValueError(
                f"run {str(r)!r} is given twice (as {where[root]!r} too): each orbit would count twice; "
                "give each run once"
            )
        where[root] = str(r)
        ident = run_identity(r)
        for h in ident["point_hashes"]:
            if h in seen:
                raise ValueError(
                    f"runs {seen[h]!r} and {str(r)!r} hold the same scene (result hash {h[:12]}…): the "
                    "same orbits twice would count each orbit twice; give each run once"
                )
            seen[h] = str(r)
        ids.append(ident)
    return ids


def _check_poolable(ids: list[dict]) -> None:
    """Runs that may be pooled into one ensemble per point: the same scene apart from ``POOLABLE_KEYS``, and
    distinct seeds (two runs of one seed share their first orbits). ValueError naming the key otherwise."""
    ref = ids[0]
    strip = lambda sc: {k: v for k, v in sc.items() if k not in POOLABLE_KEYS}  # noqa: E731
    for other in ids[1:]:
        a, b = strip(ref["scene"]), strip(other["scene"])
        diff = sorted(k for k in a.keys() | b.keys() if a.get(k) != b.get(k))
        if diff:
            k = diff[0]
            raise ValueError(
                f"pool=True: runs {ref['run']!r} and {other['run']!r} are not the same scene apart from "
                f"{'/'.join(POOLABLE_KEYS[:2])}: {k} is {a.get(k)!r} and {b.get(k)!r}"
                f"{f' (and {len(diff) - 1} more key(s))' if len(diff) > 1 else ''}; read them apart "
                "(pool=False) for one point per run"
            )
    seeds = [i["scene"].get("seed") for i in ids]
    twice = sorted({s for s in seeds if seeds.count(s) > 1}, key=str)
    if twice:
        raise ValueError(
            f"pool=True: several runs have seed {twice[0]!r}; runs of one seed share their first orbits, "
            "so pooling them counts those orbits twice: pool runs of distinct seeds"
        )


def read_arrow(run_dir, name: str = "lifetimes", columns=None, filters=None, *, allow_partial: bool = False):
    """read_arrow(run_dir, name='lifetimes', columns=None, filters=None) -> pyarrow.Table.

    The memory-lean reader: only ``columns`` are read (column projection in
    the Parquet reader), no pandas conversion. ``run_dir`` may be a URL. Every reader here reads exactly
    the run's planned, finished and verified parts (:func:`~hhscatter.data.verify.verified_dataset`); an incomplete run is an error unless
    ``allow_partial=True``.
    """
    return _scan(
        verified_dataset(run_dir, name, allow_partial=allow_partial),
        run_dir,
        name,
        columns,
        filters,
        lambda d, c, f: d.to_table(columns=c, filter=f),
    )


def survival_arrays(run_dir, filters=None, *, allow_partial: bool = False):
    """survival_arrays(run_dir, filters=None) -> (t_end float64 (N,), observed bool (N,)).

    The inputs of :func:`hhscatter.analysis.survival.fits.survival_curve`, read
    with column projection: only ``t_end`` and the dictionary codes of
    ``outcome`` are read and decoded, no pandas objects are made (~9 bytes per
    orbit). ``observed`` is False for censored orbits. Memory-bounded route for
    P(t) of 1e7+ orbits.
    """
    table = read_arrow(run_dir, "lifetimes", columns=["t_end", "outcome"], filters=filters, allow_partial=allow_partial)
    t_end = table.column("t_end").to_numpy()
    observed = np.empty(len(t_end), dtype=bool)
    pos = 0
    for chunk in table.column("outcome").chunks:
        observed[pos : pos + len(chunk)] = _observed(chunk)
        pos += len(chunk)
    return t_end, observed


def _observed(outcome) -> np.ndarray:
    """The 'observed' mask (left Ω, not censored) of a dictionary-encoded Arrow ``outcome`` array."""
    censored = np.isin(np.asarray(outcome.dictionary.to_pylist(), dtype=object), CENSORING_OUTCOMES)
    return ~censored[outcome.indices.to_numpy(zero_copy_only=False)]


def iter_survival_batches(run_dir, filters=None, *, allow_partial: bool = False):
    """iter_survival_batches(run_dir, filters=None) -> (t_end float64, observed bool) arrays per record batch.

    The lifetimes table streamed in record batches of ``t_end`` and the decoded ``outcome`` only, one part file at
    a time (its footer is dropped with its dataset): memory is one batch, whatever N. ``observed`` is False for
    censored orbits. The input of a streaming Kaplan–Meier (:func:`hhscatter.api.stream_survival`).
    """
    for part in verified_dataset(run_dir, "lifetimes", one_by_one=True, allow_partial=allow_partial):
        for batch in _scan(
            part,
            run_dir,
            "lifetimes",
            ["t_end", "outcome"],
            filters,
            lambda d, c, f: d.to_table(columns=c, filter=f).to_batches(),
        ):
            yield batch.column(0).to_numpy(), _observed(batch.column(1))


def iter_part_frames(run_dir, name: str, columns=None, filters=None, *, allow_partial: bool = False):
    """iter_part_frames(run_dir, name, columns=None, filters=None) -> pandas.DataFrame per part file, in file order.

    The rows of table ``name`` that pass ``filters`` (pushed down to the Parquet reader), ``columns`` only, one
    part file at a time: memory is one part's selected rows, whatever N. Columns and filters are checked as in
    :func:`read_lifetimes`. Parts are orbit ranges, so every orbit's rows come in one frame.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> run = tempfile.mkdtemp()
    >>> _ = hhscatter.simulate(hhscatter.Scene(energy=0.3, n=50, chunk_size=20, t_max=5.0), run,
    ...                        overwrite=True, workers=1, progress=False)
    >>> [len(df) for df in iter_part_frames(run, "lifetimes", ["traj_id"])]
    [20, 20, 10]
    """
    for part in verified_dataset(run_dir, name, one_by_one=True, allow_partial=allow_partial):
        yield _scan(part, run_dir, name, columns, filters, lambda d, c, f: d.to_table(columns=c, filter=f)).to_pandas()


def iter_parts(run_dir, name: str, columns=None, *, allow_partial: bool = False):
    """iter_parts(run_dir, name, columns=None) -> pandas.DataFrame per part file of table ``name``, in file order.

    For statistics pooled part by part (memory: one part at a time, whatever N).
    """
    for part in verified_dataset(run_dir, name, one_by_one=True, allow_partial=allow_partial):
        yield scan_checked(part, run_dir, name, lambda d: d.to_table(columns=columns)).to_pandas()


def read_lifetimes(
    run_dir: RunPath | list[RunPath],
    columns: list[str] | None = None,
    filters: pyarrow.dataset.Expression | None = None,
    *,
    categorical: bool = False,
    allow_partial: bool = False,
    pool: bool = False,
) -> pandas.DataFrame:
    """The lifetimes table of a run: one row per orbit.

    Columns: ``traj_id``, ``t_end`` (time of the orbit's end, time units), ``outcome`` ('escaped',
    'settled' — E reached E_c inside Ω, Eq. (eqn:energy_diffeq) — or 'censored' at t_max), ``exit_channel``
    (0, 1, 2 for escapes, else null), the initial state ``x0, y0, px0, py0``, ``e0`` (initial energy),
    ``e_end`` (energy at the end) and ``gamma``; a grid run adds ``energy`` (the point's nominal E0). Only the parts of the run's
    chunk plan are read, each verified (:mod:`hhscatter.data.tables`, "A run is its manifest").

    Parameters
    ----------
    run_dir : path or URL, or list of them
        A run directory written by :func:`hhscatter.simulate`. A list of runs gives their frames
        concatenated and kept apart: a ``run`` column (categorical) names each row's run as given, so that
        :func:`hhscatter.survival`, :func:`hhscatter.escape_rates` and friends see one point per run and
        grid point even where two runs share E0 and γ (e.g. two escape radii); a plain run among grid runs
        gets its ``energy`` column from its orbits' ``e0``. The same run twice (or two runs holding the
        same scene: the same orbits) is refused.
    columns : list of str, optional
        Read only these columns (projection).
    filters : pyarrow.dataset.Expression or list, optional
        Row filter, e.g. ``(ds.field("energy") == 0.3) & (ds.field("gamma") == 0.01)`` to read one grid
        point, or the same in the pandas list form ``[("energy", "==", 0.3), ("gamma", "==", 0.01)]``. A filter
        that keeps no row (a value that is not a grid point) gives an empty frame with a ``UserWarning`` naming
        the filter and the run's grid values (also in ``attrs["hhscatter"]["nothing_matched"]``).
    categorical : bool
        ``outcome`` as a pandas categorical (1 byte per orbit, for 1e7 orbits and more) instead of str.
    allow_partial : bool
        Read the finished chunks of an unfinished run, with a warning saying how much is missing.
    pool : bool
        With a list of runs: pool them into one ensemble per point, an explicit choice that is checked
        (the runs must be the same scene apart from ``seed``, ``n``, ``name``, ``batch_size`` and
        ``chunk_size``, with distinct seeds); the ``run`` column is kept (``traj_id`` repeats across runs)
        and ``DataFrame.attrs["hhscatter"]["pooled"]`` lists the runs pooled.

    Returns
    -------
    pandas.DataFrame
        ``exit_channel`` as nullable Int8. Runs in the layout of hhscatter ≤ 0.1.0 (``energy=…/gamma=…``
        folders) come back with the same columns. ``attrs["hhscatter"]`` holds what the frame was read from
        (:func:`run_identity`: the scene, its hash), where the analysis functions read E0, γ, … from.

    Raises
    ------
    RunIntegrityError
        A table or planned part is missing, a part is damaged or not in the run's plan.
    IncompleteRunError
        Chunks are unfinished and ``allow_partial`` is False.
    ValueError
        A list holds the same run (or scene) twice; ``pool=True`` with runs that differ in a scene key
        other than those above, or share a seed.
    ConfigError
        ``columns`` or a field of ``filters`` that is not a column of the table (the message lists its
        columns), ``filters`` neither an expression nor the list form.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> run = tempfile.mkdtemp()
    >>> _ = hhscatter.simulate(hhscatter.Scene(energy=0.3, n=100, seed=1, t_max=100.0), run,
    ...                        overwrite=True, workers=1, progress=False)
    >>> lt = hhscatter.read_lifetimes(run, columns=["traj_id", "t_end", "outcome"])
    >>> len(lt), sorted(set(lt.outcome) - {"escaped", "censored"})
    (100, [])
    """
    if isinstance(run_dir, (list, tuple)):
        if not run_dir:
            raise ValueError("no runs given")
        ids = _distinct_runs(run_dir)
        if pool:
            _check_poolable(ids)
        frames = [_read(r, "lifetimes", columns, filters, categorical, allow_partial) for r in run_dir]
        return _concat_runs(frames, ids, pool)
    if pool:
        raise ValueError("pool=True needs a list of runs to pool")
    return _read(run_dir, "lifetimes", columns, filters, categorical, allow_partial)


def _concat_runs(frames, ids, pool: bool = False):
    """One frame of several runs' lifetimes with a ``run`` column naming each row's run; plain runs get
    ``energy`` (their median e0, 12 digits) if any has it."""
    import pandas as pd  # deferred: pandas loads on first use

    if any("energy" in f.columns for f in frames):
        frames = [
            f
            if "energy" in f.columns or "e0" not in f.columns or not len(f)
            else f.assign(energy=float(f"{np.median(f['e0'].to_numpy(dtype=float)):.12g}"))
            for f in frames
        ]
    names = [i["run"] for i in ids]
    out = pd.concat([f.assign(run=name) for f, name in zip(frames, names)], ignore_index=True)
    out["run"] = pd.Categorical(out["run"], categories=list(dict.fromkeys(names)))
    out.attrs[FRAME_META] = {"runs": ids, "pooled": names if pool else None}
    return out


def read_by_orbit(run_dir, columns, name: str = "lifetimes", *, allow_partial: bool = False) -> dict:
    """read_by_orbit(run_dir, columns, name='lifetimes') -> {column: array}, rows in traj_id order.

    The memory-lean reader for 1e7 orbits and more: Arrow columns straight to numpy, no pandas frame and
    no Python object per orbit. Dictionary columns (``outcome``) come back as ``pandas.Categorical`` (1 byte
    per orbit); integer columns with nulls (``exit_channel``) with the nulls as −1. ``traj_id`` is always
    returned. The engine writes parts in orbit order, so the rows are reordered (copied) only if they are not.
    """
    import pyarrow as pa  # deferred: pyarrow loads on first use
    import pyarrow.compute as pc  # deferred: pyarrow loads on first use

    names = ["traj_id", *(c for c in columns if c != "traj_id")]
    tab = read_arrow(run_dir, name, columns=names, allow_partial=allow_partial)
    ids = tab.column("traj_id").to_numpy()
    order = None if bool(np.all(ids[1:] > ids[:-1])) else np.argsort(ids, kind="stable")
    out = {}
    for c in names:
        col = tab.column(c)
        if pa.types.is_dictionary(col.type):
            v = col.to_pandas().array
        elif col.null_count and pa.types.is_integer(col.type):
            v = pc.fill_null(col, -1).to_numpy()
        else:
            v = col.to_numpy()
        out[c] = v if order is None else v[order]
    del tab
    pa.default_memory_pool().release_unused()  # Arrow's allocator keeps freed buffers otherwise
    return out


def read_sections(
    run_dir: RunPath,
    columns: list[str] | None = None,
    filters: pyarrow.dataset.Expression | None = None,
    *,
    allow_partial: bool = False,
) -> pandas.DataFrame:
    """The sections table of a run: one row per crossing of the section ṙ = 0, φ̇ > 0.

    Parameters
    ----------
    run_dir : path or URL
        A run directory of a scene that recorded sections (``Scene(sections=SectionWindow(...))``).
    columns : list of str, optional
        Read only these columns.
    filters : pyarrow.dataset.Expression, optional
        Row filter.
    allow_partial : bool
        Read the finished chunks of an unfinished run, with a warning.

    Returns
    -------
    pandas.DataFrame
        ``traj_id``, ``t`` (crossing time), ``x, y, px, py``, ``energy`` (the orbit's energy at the
        crossing); a grid run adds its point's nominal E0 and γ as ``point_energy`` and ``point_gamma``.

    Raises
    ------
    RunIntegrityError
        The run has no sections table (it was not recorded), or a part is missing or damaged.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> run = tempfile.mkdtemp()
    >>> scene = hhscatter.Scene(energy=0.3, n=50, seed=1, t_max=100.0, sections=hhscatter.SectionWindow())
    >>> _ = hhscatter.simulate(scene, run, overwrite=True, workers=1, progress=False)
    >>> sec = hhscatter.read_sections(run)
    >>> bool(((sec.x * sec.px + sec.y * sec.py).abs() < 1e-10).all())     # ṙ = 0 at every crossing
    True
    """
    return _read(run_dir, "sections", columns, filters, allow_partial=allow_partial)


def read_snapshots(
    run_dir: RunPath,
    columns: list[str] | None = None,
    filters: pyarrow.dataset.Expression | None = None,
    *,
    allow_partial: bool = False,
) -> pandas.DataFrame:
    """The snapshots table of a run: the energy of every orbit still alive at each snapshot time.

    Parameters
    ----------
    run_dir : path or URL
        A run directory of a scene that recorded snapshots (``Scene(snapshots=[t1, t2, …])``).
    columns : list of str, optional
        Read only these columns.
    filters : pyarrow.dataset.Expression, optional
        Row filter.
    allow_partial : bool
        Read the finished chunks of an unfinished run, with a warning.

    Returns
    -------
    pandas.DataFrame
        ``traj_id``, ``t`` (snapshot time), ``energy``; a grid run adds ``point_energy``, ``point_gamma``.
        With drag, ⟨E⟩(t) of these rows is the paper's Fig. 3 (Eq. (eqn:energy_exp_decay)).

    Raises
    ------
    RunIntegrityError
        The run has no snapshots table, or a part is missing or damaged.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> run = tempfile.mkdtemp()
    >>> scene = hhscatter.Scene(energy=0.3, gamma=0.01, n=50, seed=1, t_max=50.0, snapshots=[0.0, 10.0])
    >>> _ = hhscatter.simulate(scene, run, overwrite=True, workers=1, progress=False)
    >>> snaps = hhscatter.read_snapshots(run)
    >>> bool((snaps.groupby("t").energy.mean().diff().dropna() < 0).all())   # drag: ⟨E⟩ falls
    True
    """
    return _read(run_dir, "snapshots", columns, filters, allow_partial=allow_partial)


def read_crossings(run_dir, columns=None, filters=None, *, allow_partial: bool = False):
    """read_crossings(run_dir, ...) -> DataFrame traj_id, t, radius, direction (follow scenes)."""
    return _read(run_dir, "crossings", columns, filters, allow_partial=allow_partial)
