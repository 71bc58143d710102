"""Write part files: one Parquet file per chunk and table, atomically, with page checksums and the run's
metadata (the layout and schemas: :mod:`hhscatter.data.schema`)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from hhscatter.data.store import Store

if TYPE_CHECKING:  # annotations only
    pass
from hhscatter.data.schema import META_KEY


def write_part(path, table, meta: dict, store=None, *, sync_dir: bool = True) -> None:
    """write_part(path, table, meta, store=None, sync_dir=True) -> None: write ``table`` with metadata ``meta``
    atomically (``sync_dir``: :meth:`hhscatter.data.store.Store.write_atomic`'s).

    ``path`` is a local path, or, with ``store`` (a :class:`hhscatter.data.store.Store`),
    a path relative to the store's root. The file is written to a temporary
    name, fsync'ed and renamed (see :mod:`hhscatter.data.store`), so a part file
    under its final name is always complete. Parquet page checksums are
    written so that ``verify_part`` detects damaged data pages, not only a
    damaged footer.
    """
    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    if store is None:
        path = Path(path)
        store, rel = Store(path.parent), path.name
    else:
        rel = str(path)
    table = table.replace_schema_metadata({META_KEY: json.dumps(meta, sort_keys=True).encode()})

    def write(target, filesystem):
        # no per-file timestamps or writer-dependent fields: same rows, same bytes
        opts = {
            "compression": "zstd",
            "write_statistics": True,
            "write_page_checksum": True,
            "use_dictionary": dictionary_columns(table.schema),
        }
        if filesystem is None:  # our own handle, closed even when the write fails (a full disk): a worker
            with open(target, "wb") as fh:  # that keeps the error must not keep the unlinked file open
                pq.write_table(table, fh, **opts)
        else:
            pq.write_table(table, target, filesystem=filesystem, **opts)

    store.write_atomic(rel, write, sync_dir=sync_dir)


def dictionary_columns(schema) -> list:
    """dictionary_columns(schema) -> names of the columns worth Parquet's dictionary encoding: all but the
    float64 and int64 ones (orbit states, times and ids, nearly all distinct: pyarrow built a dictionary for
    each and dropped it again, 35 % of a lifetimes part's write time). Dictionary-typed columns
    keep their encoding, so every table reads back the same (types included); zstd still compresses the
    plain columns (a constant column to a few bytes)."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    return [f.name for f in schema if not (pa.types.is_float64(f.type) or pa.types.is_int64(f.type))]


def write_parts_streamed(path, tables, meta: dict) -> int:
    """write_parts_streamed(path, tables, meta) -> rows written: one Parquet file from an iterable of Arrow tables.

    The tables (same columns and types; dictionary columns may have different
    dictionaries) are written one row group after the other with a
    ``ParquetWriter``, so only one of them is in memory at a time, and the
    file appears atomically under ``path`` (as :func:`write_part`, with the
    same options and metadata key).
    """
    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    path = Path(path)
    store, rows = Store(path.parent), [0]

    def write(target, filesystem):
        writer = None
        try:
            for t in tables:
                if writer is None:
                    schema = t.schema.with_metadata({META_KEY: json.dumps(meta, sort_keys=True).encode()})
                    writer = pq.ParquetWriter(
                        target,
                        schema,
                        filesystem=filesystem,
                        compression="zstd",
                        write_statistics=True,
                        write_page_checksum=True,
                    )
                writer.write_table(t.replace_schema_metadata(schema.metadata))
                rows[0] += t.num_rows
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            raise ValueError(f"{path}: no table to write")

    store.write_atomic(path.name, write)
    return rows[0]
