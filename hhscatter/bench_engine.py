"""``make bench-engine``: µs per orbit of the engine, 1 worker and all workers.

    python -m hhscatter.bench_engine [-n N] [--tol TOL]

Scenes: E = 0.27, γ = 0 and E0 = 0.3, γ = 0.01 (disk ICs, t_max = 5000).
Also reports the share of a single-worker chunk spent inside heyoka's
compiled code (``propagate_until`` self time under cProfile, callbacks
excluded) and the steps per orbit. Not a test: numbers vary with the machine.
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import tempfile
import time

import numpy as np


def compiled_share(scene, n=10000):
    from .engine import run_chunk
    from .ics import region_ics

    ics = region_ics(scene, 0, n)
    run_chunk(scene, ics[:64], np.arange(64))  # JIT outside the measurement
    prof = cProfile.Profile()
    t0 = time.perf_counter()
    prof.enable()
    res = run_chunk(scene, ics, np.arange(n))
    prof.disable()
    total = time.perf_counter() - t0
    stats = pstats.Stats(prof).stats
    inside = sum(v[2] for k, v in stats.items() if "propagate_until" in k[2])
    prof_total = sum(v[2] for v in stats.values())
    return inside / prof_total, res.n_steps / n, total


def main(argv=None):
    from .runner import default_workers, simulate
    from .scene import Scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=100_000)
    ap.add_argument("--tol", type=float, default=1e-15)
    a = ap.parse_args(argv)
    scenes = [
        Scene(energy=0.27, n=a.n, seed=1, tol=a.tol, name="E=0.27,γ=0"),
        Scene(energy=0.3, gamma=0.01, n=a.n, seed=1, tol=a.tol, name="E0=0.3,γ=0.01"),
    ]
    allw = default_workers()
    print(f"# hhscatter engine benchmark: N = {a.n}, tol = {a.tol:g}, {allw} cores")
    print(f"{'scene':16s} {'workers':>7s} {'wall s':>8s} {'µs/orbit':>9s} {'µs/orbit/core':>14s}")
    for sc in scenes:
        for w in sorted({1, allw}):
            with tempfile.TemporaryDirectory() as d:
                s = simulate(sc, d, workers=w, progress=False)
            print(f"{sc.name:16s} {w:7d} {s.wall_seconds:8.2f} {1e6 * s.wall_seconds / sc.n:9.2f} "
                  f"{1e6 * s.compute_seconds / sc.n:14.2f}")
    for sc in scenes:
        share, steps, _ = compiled_share(sc)
        print(f"{sc.name:16s} share of time inside heyoka's compiled propagate_until: {100 * share:.0f}% "
              f"({steps:.1f} steps/orbit)")


if __name__ == "__main__":
    main()
