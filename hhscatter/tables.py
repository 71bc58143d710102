"""Parquet tables: the contract for external analysis.

A run directory holds one dataset per table, one part file per chunk::

    OUT/lifetimes/part-000000.parquet
    OUT/sections/part-000000.parquet     (only when the scene records sections)
    OUT/snapshots/part-000000.parquet    (only when the scene records snapshots)
    OUT/scene.json                       (the scene, for humans; each part carries it too)

Every part file's key-value metadata holds, under the key ``hhscatter``, a
JSON document with the full scene, its result hash, the chunk index and
orbit range, the row count, and the versions of hhscatter, heyoka, numpy and
pyarrow plus the git commit when available: a table alone says how it was
made. Files are written to a temporary name and renamed when complete.

Schemas
-------
lifetimes: traj_id int64, x0 y0 px0 py0 e0 gamma float64,
           outcome dictionary<string> ('escaped' | 'settled' | 'censored'),
           t_end float64 (escape time: root of the r = r_esc crossing; settling
           time: root of E = E_c; or t_max), exit_channel int8 (null unless
           escaped; channel k is centred on the angle π/2 + 2πk/3),
           e_end float64 (energy at t_end)
sections:  traj_id int64, t x y px py energy float64
snapshots: traj_id int64, t energy float64
"""
from __future__ import annotations

import functools
import json
import os
import subprocess
from pathlib import Path

import numpy as np

META_KEY = b"hhscatter"
TABLES = ("lifetimes", "sections", "snapshots")


def _schemas():
    import pyarrow as pa

    f64 = pa.float64()
    return {
        "lifetimes": pa.schema(
            [
                ("traj_id", pa.int64()),
                ("x0", f64),
                ("y0", f64),
                ("px0", f64),
                ("py0", f64),
                ("e0", f64),
                ("gamma", f64),
                ("outcome", pa.dictionary(pa.int8(), pa.string())),
                ("t_end", f64),
                ("exit_channel", pa.int8()),
                ("e_end", f64),
            ]
        ),
        "sections": pa.schema(
            [("traj_id", pa.int64())] + [(c, f64) for c in ("t", "x", "y", "px", "py", "energy")]
        ),
        "snapshots": pa.schema([("traj_id", pa.int64()), ("t", f64), ("energy", f64)]),
    }


@functools.lru_cache(maxsize=1)
def provenance() -> dict:
    """Versions of the software that made a table, and the git commit if known."""
    import heyoka
    import pyarrow

    from . import __version__

    commit = None
    try:
        here = Path(__file__).resolve().parent
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=here, capture_output=True, text=True, timeout=5, check=False
        )
        if out.returncode == 0:
            commit = out.stdout.strip()
            dirty = subprocess.run(
                ["git", "status", "--porcelain", "--untracked-files=no"],
                cwd=here, capture_output=True, text=True, timeout=5, check=False,
            )
            if dirty.returncode == 0 and dirty.stdout.strip():
                commit += "-dirty"
    except (OSError, subprocess.SubprocessError):
        pass
    return {
        "hhscatter": __version__,
        "heyoka": heyoka.__version__,
        "numpy": np.__version__,
        "pyarrow": pyarrow.__version__,
        "git_commit": commit,
    }


def to_arrow(name: str, columns: dict):
    """to_arrow(name, columns) -> pyarrow.Table with the table's fixed schema."""
    import pyarrow as pa

    schema = _schemas()[name]
    arrays = []
    for field in schema:
        col = columns[field.name]
        if name == "lifetimes" and field.name == "outcome":
            from .engine import OUTCOMES

            codes = np.asarray(col, dtype=np.int8)
            arrays.append(pa.DictionaryArray.from_arrays(pa.array(codes, pa.int8()), pa.array(OUTCOMES)))
        elif name == "lifetimes" and field.name == "exit_channel":
            ch = np.asarray(col, dtype=np.int8)
            arrays.append(pa.array(ch, pa.int8(), mask=ch < 0))
        else:
            arr = np.asarray(col)
            if arr.dtype.kind == "f" and not np.isfinite(arr).all():
                raise FloatingPointError(f"{name}.{field.name}: non-finite values must never reach a table")
            arrays.append(pa.array(arr, field.type))
    return pa.Table.from_arrays(arrays, schema=schema)


def write_part(path: Path, table, meta: dict) -> None:
    """Write ``table`` with metadata ``meta`` to ``path`` atomically (tmp + fsync + rename)."""
    import pyarrow.parquet as pq

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    table = table.replace_schema_metadata({META_KEY: json.dumps(meta, sort_keys=True).encode()})
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        # no per-file timestamps or writer-dependent fields: same rows, same bytes
        pq.write_table(table, tmp, compression="zstd", write_statistics=True)
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def part_name(chunk: int) -> str:
    return f"part-{chunk:06d}.parquet"


def read_meta(path) -> dict:
    """read_meta(path) -> the ``hhscatter`` metadata dict of one part file."""
    import pyarrow.parquet as pq

    md = pq.read_schema(path).metadata or {}
    if META_KEY not in md:
        raise ValueError(f"{path} is not an hhscatter table (no '{META_KEY.decode()}' metadata)")
    return json.loads(md[META_KEY])


def _read(run_dir, name: str, columns=None, filters=None):
    import pyarrow.dataset as ds

    base = Path(run_dir)
    path = base / name if (base / name).is_dir() else base
    if not path.exists():
        raise FileNotFoundError(f"no {name} table at {path}")
    files = sorted(str(p) for p in path.glob("part-*.parquet"))
    if not files:
        raise FileNotFoundError(f"no part files in {path}")
    dataset = ds.dataset(files, format="parquet", schema=_schemas()[name])
    table = dataset.to_table(columns=columns, filter=filters)
    df = table.to_pandas()
    if "outcome" in df.columns:
        df["outcome"] = df["outcome"].astype(str)
    if "exit_channel" in df.columns:
        df["exit_channel"] = df["exit_channel"].astype("Int8")
    return df


def read_lifetimes(run_dir, columns=None, filters=None):
    """read_lifetimes(run_dir, columns=None, filters=None) -> pandas.DataFrame of the lifetimes table.

    ``columns`` projects (only those columns are read); ``filters`` is a
    pyarrow.dataset expression. ``outcome`` comes back as str, ``exit_channel``
    as nullable Int8.
    """
    return _read(run_dir, "lifetimes", columns, filters)


def read_sections(run_dir, columns=None, filters=None):
    """read_sections(run_dir, ...) -> DataFrame traj_id, t, x, y, px, py, energy."""
    return _read(run_dir, "sections", columns, filters)


def read_snapshots(run_dir, columns=None, filters=None):
    """read_snapshots(run_dir, ...) -> DataFrame traj_id, t, energy."""
    return _read(run_dir, "snapshots", columns, filters)
