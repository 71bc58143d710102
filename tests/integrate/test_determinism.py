"""Determinism of the stream (and epoch) scheduler with many censored orbits: the same orbits give byte-identical tables
whatever the chunk size and the batch size (README: "whatever workers/backend/chunk size").

A per-orbit propagation bound (lane start + t_max) would make the censored state depend on the
lane's start time (the bound's rounding clamps the last step), and an orbit whose ending event fell in a step
clamped by an earlier orbit's (stale) bound would end an ulp elsewhere (the event root is found on the clamped step).
Short t_max: a tenth of the orbits are censored, and lanes refill often (many stale bounds). The reference is the
same orbits run a batch at a time (each orbit alone in its lane from lane time 0), an independent schedule."""

from __future__ import annotations

import numpy as np
import pytest

from hhscatter.integrate.engine import CENSORED, ESCAPED, run_chunk
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene, SectionWindow


def _split(scene, ics, ids, size, batch_size=None):
    parts = [
        run_chunk(scene, ics[a : a + size], ids[a : a + size], batch_size=batch_size).tables()
        for a in range(0, len(ics), size)
    ]
    return {name: {c: np.concatenate([p[name][c] for p in parts]) for c in cols} for name, cols in parts[0].items()}


def _assert_bitwise(a, b, what):
    for name, cols in a.items():
        for col, v in cols.items():
            w = b[name][col]
            assert v.dtype == w.dtype and v.shape == w.shape, (what, name, col)
            assert v.tobytes() == w.tobytes(), (what, name, col, int((v != w).sum()))


@pytest.mark.parametrize(
    "kw",
    [
        {"gamma": 0.01, "energy": 0.3},  # the no-return rule (linear drag, default r_far)
        {"gamma": 0.01, "energy": 0.3, "r_far": 10.0},  # the scene's own far event
        {"gamma": 0.0, "energy": 0.3},  # conservative: escapes in steps clamped by stale bounds moved an ulp
        {"gamma": 0.01, "energy": 0.3, "sections": SectionWindow(), "r_far": 10.0},  # generic handlers, section rows
        # orbit 556's escape time is exactly halfway between two doubles (the exact sum of its steps): the lane's
        # double-length time carries ~1e-30 of error that depends on the lane's start and decided the rounding
        # (t_end differed by 1 ulp with chunks of 300) until near-ties rounded to even (orbit_time._tie_to_even)
        {"gamma": 0.01, "energy": 0.3, "sections": SectionWindow()},
    ],
    ids=["no-return", "own-r_far", "conservative", "sections", "sections-no-return-tie"],
)
def test_censoring_scenes_do_not_depend_on_chunk_or_batch_size(kw):
    sc = Scene(n=2000, seed=5, r_esc=1.03, t_max=20.0, **kw)
    ics = region_ics(sc, 0, sc.n)
    ids = np.arange(sc.n, dtype=np.int64)
    whole = run_chunk(sc, ics, ids).tables()
    out = whole["lifetimes"]["outcome"]
    assert (out == CENSORED).sum() > 40 and (out == ESCAPED).sum() > 1000
    _assert_bitwise(whole, _split(sc, ics, ids, 8), "alone")  # each orbit alone in its lane from time 0
    _assert_bitwise(whole, _split(sc, ics, ids, 300), "chunks of 300")
    _assert_bitwise(whole, _split(sc, ics, ids, 700, batch_size=4), "chunks of 700, 4 lanes")


def test_epoch_scheduler_tables_do_not_depend_on_chunk_or_batch_size():
    """Snapshots every 0.5 and the first section after t = 17 (the epoch scheduler, the recording bench's scene at
    t_max = 40): lanes parked mid-epoch, refilled at epoch ends, and the snapshot rows gathered in bulk give the
    same bytes whatever the chunking and the lanes."""
    snaps = tuple(float(t) for t in np.arange(0.0, 30.0 + 1e-9, 0.5))
    sc = Scene(
        energy=0.3,
        gamma=0.01,
        n=600,
        seed=3,
        r_esc=1.03,
        t_max=40.0,
        snapshots=snaps,
        sections=SectionWindow(t_from=17.0, first_only=True),
    )
    ics = region_ics(sc, 0, sc.n)
    ids = np.arange(sc.n, dtype=np.int64)
    whole = run_chunk(sc, ics, ids).tables()
    assert (whole["lifetimes"]["outcome"] == CENSORED).any() and len(whole["sections"]["t"]) > 10
    assert len(whole["snapshots"]["t"]) > 5 * sc.n
    _assert_bitwise(whole, _split(sc, ics, ids, 8), "alone")  # each orbit alone in its lane from epoch 0
    _assert_bitwise(whole, _split(sc, ics, ids, 97, batch_size=4), "chunks of 97, 4 lanes")
    _assert_bitwise(whole, _split(sc, ics, ids, 250, batch_size=8), "chunks of 250, 8 lanes")
