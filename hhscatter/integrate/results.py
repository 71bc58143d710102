"""A chunk's rows: :class:`ChunkResult` and the columns of its tables."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hhscatter.outcomes import TABLE_COLUMNS

SECTION_COLUMNS = TABLE_COLUMNS["sections"]
CROSSING_COLUMNS = TABLE_COLUMNS["crossings"]


@dataclass
class ChunkResult:
    """Rows produced by one chunk (plain numpy arrays, table column order)."""

    lifetimes: dict
    sections: dict
    snapshots: dict
    crossings: dict
    n_returns: int = 0
    n_steps: int = 0
    event_failures: int = 0  # heyoka's event-detection failures logged while the chunk ran (each one redone)
    redone: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64))  # traj_ids redone on the reference
    tangent_beyond: int = 0  # orbits whose log-stretch Λ passed events.MAX_LOG_STRETCH (the tangent dynamics)

    def tables(self) -> dict:
        return {
            "lifetimes": self.lifetimes,
            "sections": self.sections,
            "snapshots": self.snapshots,
            "crossings": self.crossings,
        }


def _empty_result(traj_ids) -> ChunkResult:
    """A chunk result without orbits."""
    crossings = _rows_to_columns([], CROSSING_COLUMNS, traj_ids)
    crossings["direction"] = crossings["direction"].astype(np.int8)
    return ChunkResult(
        {},
        _rows_to_columns([], SECTION_COLUMNS, traj_ids),
        _rows_to_columns([], ("traj_id", "t", "energy"), traj_ids),
        crossings,
    )


def _rows_to_columns(rows, columns, traj_ids):
    """Rows (local orbit index first) -> dict of columns sorted by (traj_id, t)."""
    if not rows:
        out = {c: np.empty(0) for c in columns}
        out["traj_id"] = np.empty(0, dtype=np.int64)
        return out
    arr = np.array(rows, dtype=float)
    local = arr[:, 0].astype(np.int64)
    order = np.lexsort((arr[:, 1], local))
    arr = arr[order]
    out = {c: np.ascontiguousarray(arr[:, i]) for i, c in enumerate(columns)}
    out["traj_id"] = traj_ids[local[order]]
    return out
