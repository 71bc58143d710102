"""Parquet tables: the contract for external analysis (schemas, layout, metadata; writers in
:mod:`hhscatter.data.write`, verified readers in :mod:`hhscatter.data.read`).

A run directory holds one dataset per table, one part file per chunk::

    OUT/lifetimes/part-000000.parquet
    OUT/sections/part-000000.parquet     (only when the scene records sections)
    OUT/snapshots/part-000000.parquet    (only when the scene records snapshots)
    OUT/scene.json                       (the scene, for humans; each part carries it too)

A grid run (a sweep over E0 and/or γ, see :mod:`hhscatter.scene.grid`) has one
folder per grid point in each table, and every file carries its point as
ordinary numeric columns::

    OUT/lifetimes/E0.25_gamma0.01/part-000000.parquet

The folder names contain no ``=``: they are not hive partition keys, so no
reader derives a (string-typed, column-shadowing) key from them, and every
reader -- :func:`read_lifetimes`, ``pandas.read_parquet(OUT/"lifetimes")``,
``pyarrow.dataset.dataset(…, partitioning="hive")``, DuckDB
``read_parquet('OUT/lifetimes/**/*.parquet', hive_partitioning=true)`` and
polars ``scan_parquet(…, hive_partitioning=True)`` -- returns the same rows
with float64 point columns: ``energy`` (the point's nominal E0; the per-orbit
``e0`` column keeps each orbit's computed initial energy, which differs from
it in the last bits) and ``gamma`` in ``lifetimes``; ``point_energy`` and
``point_gamma`` in ``sections`` and ``snapshots``, whose ``energy`` column is
the orbit's energy at ``t``. Select a point with a filter on these columns
(Parquet statistics skip the other points' files). A plain (single-scene)
run has no point folders and no extra columns. ``OUT`` may be a URL
(``s3://…``, any fsspec protocol; ``pip install 'hhscatter[cloud]'``).

Runs written before this layout (hhscatter ≤ 0.1.0 grid runs, hive folders
``energy=0.25/gamma=0.01/`` whose keys clash with the files' columns) are
still read by the functions here, which give them the same columns as the new
layout; ``--resume`` continues such a run in its own layout.

Reading is verified (:func:`~hhscatter.data.verify.verified_dataset`): a run read by these functions is read
as exactly the part files its manifest (``scene.json``) plans and that are
finished, each checked against the plan (scene hash, chunk, orbit range, row
count) with its data pages' checksums verified. A missing table or part, a part
outside the plan, of another scene or damaged raise :class:`RunIntegrityError`
(exit status 2 in the CLI); an unfinished run raises :class:`IncompleteRunError`
unless ``allow_partial=True``, which reads the finished chunks of every table
alike (so sections/snapshots never hold an orbit without a lifetimes row) and
warns how much is missing. Readers outside hhscatter (pandas, DuckDB, polars)
see the files but none of these checks.

Every part file's key-value metadata holds, under the key ``hhscatter``, a
JSON document with the full scene, its result hash, the chunk index and
orbit range, the row count, and the versions of hhscatter, heyoka, numpy and
pyarrow plus the git commit when available: a table alone says how it was
made. Files are written to a temporary name and renamed when complete, with
Parquet page checksums (see :func:`~hhscatter.data.verify.verify_part`).

Schemas
-------
lifetimes: traj_id int64, x0 y0 px0 py0 e0 gamma float64,
           outcome dictionary<string> ('escaped' | 'settled' | 'censored' | 'stopped'),
           t_end float64 (escape time: root of the r = r_esc crossing; settling
           time: root of E = E_c; or t_max), exit_channel int8 (null unless
           escaped; channel k is centred on the angle π/2 + 2πk/3),
           e_end float64 (energy at t_end)
           [log_stretch float64: scenes with ``tangent = true`` only: Λ at t_end, the log-stretch of the
           tangent vector (the finite-time Lyapunov exponent is log_stretch/t_end)]
sections:  traj_id int64, t x y px py energy float64
snapshots: traj_id int64, t energy float64 (with ``continue_settled``: also settled
           orbits after t_end)
crossings: traj_id int64, t radius float64, direction int8 (+1 outward, −1 inward);
           follow scenes only: every crossing of the follow radii
"""

from __future__ import annotations

import functools
import importlib.metadata
import os
import subprocess
from pathlib import Path
from typing import TYPE_CHECKING, Union

import numpy as np

from hhscatter._version import ENGINE_REVISION, __version__
from hhscatter.outcomes import OUTCOMES, TABLE_COLUMNS

if TYPE_CHECKING:  # annotations only
    pass

RunPath = Union[str, "os.PathLike[str]"]  # a run directory (or a URL pyarrow/fsspec can read)


META_KEY = b"hhscatter"


TABLES = ("lifetimes", "sections", "snapshots", "crossings")

#: columns a table has only when its scene asks for them (appended after the fixed ones, float64)
OPTIONAL_COLUMNS = {"lifetimes": ("log_stretch",)}


@functools.lru_cache(maxsize=1)
def _schemas():
    import pyarrow as pa  # deferred: pyarrow loads on first use

    f64 = pa.float64()
    # the columns are declared once (hhscatter.outcomes.TABLE_COLUMNS); here their types (float64 unless named)
    types = {
        "traj_id": pa.int64(),
        "outcome": pa.dictionary(pa.int8(), pa.string()),
        "exit_channel": pa.int8(),
        "direction": pa.int8(),
    }
    return {name: pa.schema([(c, types.get(c, f64)) for c in columns]) for name, columns in TABLE_COLUMNS.items()}


def git_commit(where: Path, *, length: int | None = None, timeout: float = 5) -> str | None:
    """The commit checked out in the git work tree holding ``where`` (``length`` hex digits, all when None), with
    "-dirty" when tracked files differ from it; None when there is no git or no work tree.

    Examples
    --------
    >>> c = git_commit(Path("."))
    >>> c is None or len(c.removesuffix("-dirty")) >= 7
    True
    """

    def git(*args):
        return subprocess.run(["git", *args], cwd=where, capture_output=True, text=True, timeout=timeout, check=False)

    try:
        out = git("rev-parse", f"--short={length}" if length else "HEAD", *(["HEAD"] if length else []))
        if out.returncode != 0:
            return None
        dirty = git("status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() + ("-dirty" if dirty.returncode == 0 and dirty.stdout.strip() else "")


@functools.lru_cache(maxsize=1)
def provenance() -> dict:
    """Versions of the software that made a table, and the git commit if known."""
    import pyarrow  # deferred: pyarrow loads on first use

    commit = git_commit(Path(__file__).resolve().parent)
    return {
        "hhscatter": __version__,
        "engine_revision": ENGINE_REVISION,
        "heyoka": importlib.metadata.version("heyoka"),  # the installed distribution's: heyoka is the engine's
        "numpy": np.__version__,
        "pyarrow": pyarrow.__version__,
        "git_commit": commit,
    }


def to_arrow(name: str, columns: dict):
    """to_arrow(name, columns) -> pyarrow.Table with the table's fixed schema (and those of its
    :data:`OPTIONAL_COLUMNS` that ``columns`` holds)."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    schema = schema_of(name, optional=[c for c in OPTIONAL_COLUMNS.get(name, ()) if c in columns])
    arrays = []
    for field in schema:
        col = columns[field.name]
        if name == "lifetimes" and field.name == "outcome":
            codes = np.asarray(col, dtype=np.int8)
            arrays.append(
                pa.DictionaryArray.from_buffers(field.type, len(codes), [None, pa.py_buffer(codes)], _outcome_names())
            )
        elif name == "lifetimes" and field.name == "exit_channel":
            ch = np.asarray(col, dtype=np.int8)
            arrays.append(_arrow(ch, pa.int8(), mask=ch < 0))
        else:
            arr = np.asarray(col)
            if arr.dtype.kind == "f" and not np.isfinite(arr).all():
                raise FloatingPointError(f"{name}.{field.name}: non-finite values must never reach a table")
            arrays.append(_arrow(arr, field.type))
    return pa.Table.from_arrays(arrays, schema=schema)


@functools.lru_cache(maxsize=1)
def _outcome_names():
    """The outcome column's dictionary (``OUTCOMES``) as an Arrow string array, from its buffers (see :func:`_arrow`)."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    enc = [o.encode() for o in OUTCOMES]
    offsets = np.concatenate([[0], np.cumsum([len(e) for e in enc])]).astype(np.int32)
    return pa.Array.from_buffers(pa.string(), len(enc), [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(enc))])


_NUMPY_OF = {"double": np.float64, "int64": np.int64, "int8": np.int8}  # the Arrow types of the fixed schemas


def _arrow(arr, typ, mask=None):
    """_arrow(arr, typ, mask=None) -> the Arrow array ``pa.array(arr, typ, mask=mask)`` made from the numpy
    buffer itself: the same values, validity and buffers (masked slots keep their values, as in pa.array), without ``pa.array``'s check for pandas objects,
    which imports pandas (~0.5 s of every ``simulate`` process)."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    a = np.ascontiguousarray(arr, dtype=_NUMPY_OF[str(typ)])
    validity, nulls = None, 0
    if mask is not None and mask.any():
        validity, nulls = pa.py_buffer(np.packbits(~mask, bitorder="little")), int(mask.sum())
    return pa.Array.from_buffers(typ, len(a), [validity, pa.py_buffer(a)], null_count=nulls)


def part_name(chunk: int) -> str:
    return f"part-{chunk:06d}.parquet"


#: folder keys of grid runs written by hhscatter ≤ 0.1.0 (``energy=…/gamma=…``), read by :func:`~hhscatter.data.verify.verified_dataset`
LEGACY_PARTITION_KEYS = ("energy", "gamma")


#: the columns a grid run's files carry to name their point: (column, Scene field) per table
POINT_COLUMNS = {
    "lifetimes": (("energy", "energy"),),  # ``gamma`` is a lifetimes column already
    "sections": (("point_energy", "energy"), ("point_gamma", "gamma")),
    "snapshots": (("point_energy", "energy"), ("point_gamma", "gamma")),
    "crossings": (("point_energy", "energy"), ("point_gamma", "gamma")),
}


def schema_of(name: str, grid: bool = False, optional=()):
    """schema_of(name, grid=False, optional=()) -> pyarrow.Schema of a table (with the ``optional`` columns of
    :data:`OPTIONAL_COLUMNS` it holds, then the point columns of a grid run)."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    schema = _schemas()[name]
    if optional:
        schema = pa.schema(list(schema) + [pa.field(c, pa.float64()) for c in optional])
    if grid:
        schema = pa.schema(list(schema) + [pa.field(c, pa.float64()) for c, _ in POINT_COLUMNS[name]])
    return schema


def add_point_columns(name: str, table, scene):
    """add_point_columns(name, table, scene) -> ``table`` with the grid point's constant columns appended."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    for col, key in POINT_COLUMNS[name]:
        table = table.append_column(
            pa.field(col, pa.float64()), pa.array(np.full(table.num_rows, float(getattr(scene, key))))
        )
    return table


def legacy_point(rel: str):
    """legacy_point('energy=0.25/gamma=0.01/part-….parquet') -> (0.25, 0.01), or None if not that layout."""
    keys = dict(seg.split("=", 1) for seg in rel.split("/")[:-1] if "=" in seg)
    if set(keys) != set(LEGACY_PARTITION_KEYS):
        return None
    return tuple(float(keys[k]) for k in LEGACY_PARTITION_KEYS)


# RunIntegrityError, IncompleteRunError: hhscatter.errors (importable from here, as before)
