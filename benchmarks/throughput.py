"""Engine throughput (part of ``make bench``): µs per orbit with 1 and all workers, extrapolated to N = 1e7.

Scenes: E = 0.23, 0.27, 0.35 with γ = 0 and E0 = 0.3 with γ ∈ {1e-3, 1e-2}
(disk ICs, t_max = 5000, tol from the config). Each worker process compiles
the integrator first (heyoka's JIT, ~1 s, once per process: negligible for a
1e7-orbit run), then the timed phase integrates N orbits split into chunks
over the pool. Reported: wall µs/orbit (what the user waits), CPU µs/orbit/core
(sum of chunk times / N) and the wall time extrapolated to ``extrapolate_n``
orbits (linear in N: orbits are independent).
"""

from __future__ import annotations

import json
import os
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from hhscatter.integrate.engine import run_chunk


def _warm(scene_json):
    """Pool initializer: compile the scene's integrator in this process (outside the timing)."""
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import scene_from_dict  # deferred: pydantic loads on first use

    sc = scene_from_dict(json.loads(scene_json))
    run_chunk(sc, region_ics(sc, 0, 16), np.arange(16))


def _hold(seconds):
    time.sleep(seconds)
    return os.getpid()


def _chunk(scene_json, start, stop):
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import scene_from_dict  # deferred: pydantic loads on first use

    sc = scene_from_dict(json.loads(scene_json))
    ics = region_ics(sc, start, stop)
    t0 = time.perf_counter()
    res = run_chunk(sc, ics, np.arange(start, stop))
    return time.perf_counter() - t0, np.bincount(res.lifetimes["outcome"], minlength=3)


def measure_one(scene, workers):
    """measure_one(scene, workers) -> dict: wall and CPU µs/orbit of ``scene.n`` orbits on ``workers`` processes."""
    sj = scene.to_json()
    n = scene.n
    nchunks = max(4 * workers, 1)
    edges = np.linspace(0, n, nchunks + 1).astype(int)
    with ProcessPoolExecutor(max_workers=workers, initializer=_warm, initargs=(sj,)) as ex:
        # start every worker (each compiles in its initializer) before the clock starts
        list(ex.map(_hold, [0.3] * workers))
        t0 = time.perf_counter()
        futs = [ex.submit(_chunk, sj, int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]
        res = [f.result() for f in futs]
        wall = time.perf_counter() - t0
    cpu = sum(r[0] for r in res)
    oc = sum(r[1] for r in res)
    return {
        "wall_s": wall,
        "us_wall": 1e6 * wall / n,
        "us_cpu_per_core": 1e6 * cpu / n,
        "escaped": int(oc[0]),
        "settled": int(oc[1]),
        "censored": int(oc[2]),
    }


def measure_throughput(cfg, *, progress=True):
    """measure_throughput(cfg) -> DataFrame, one row per (scene, workers)."""
    import pandas as pd  # deferred: pandas loads on first use

    from hhscatter.run.worker import default_workers  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    tp = cfg["throughput"]
    b = cfg["bench"]
    scenes = [Scene(energy=E, n=tp["n"], seed=b["seed"], tol=tp["tol"], name=f"E={E:g}, γ=0") for E in tp["energies"]]
    scenes += [
        Scene(
            energy=tp["dissipative_energy"],
            gamma=g,
            n=tp["n"],
            seed=b["seed"],
            tol=tp["tol"],
            name=f"E0={tp['dissipative_energy']:g}, γ={g:g}",
        )
        for g in tp["gammas"]
    ]
    allw = default_workers()
    rows = []
    for sc in scenes:
        for w in sorted({1, allw}):
            r = measure_one(sc, w)
            r.update(
                {
                    "scene": sc.name,
                    "workers": w,
                    "n": sc.n,
                    "extrapolated_wall_s": r["us_wall"] * 1e-6 * tp["extrapolate_n"],
                }
            )
            rows.append(r)
            if progress:
                print(
                    f"  {sc.name:16s} workers={w}: {r['us_wall']:.1f} µs/orbit wall, "
                    f"{r['us_cpu_per_core']:.1f} µs/orbit/core",
                    flush=True,
                )
    return pd.DataFrame(rows)


def throughput_markdown(df, cfg):
    """throughput_markdown(df, cfg) -> markdown table of :func:`measure_throughput`'s rows."""
    n_ex = cfg["throughput"]["extrapolate_n"]
    L = [
        "## Engine throughput",
        "",
        f"tol = {cfg['throughput']['tol']:g}, disk ICs, t_max = 5000, N = {int(df.n.iloc[0])} per row; compile time "
        "excluded (once per process). Wall µs/orbit on a shared machine: the all-worker rows are only as "
        "parallel as the other jobs on the machine allowed.",
        "",
        f"| scene | workers | wall µs/orbit | CPU µs/orbit/core | escaped / settled / censored | "
        f"wall for N = {n_ex:.0e} |",
        "|---|---|---|---|---|---|",
    ]
    for _, r in df.iterrows():
        h = r.extrapolated_wall_s / 3600
        L.append(
            f"| {r.scene} | {r.workers} | {r.us_wall:.1f} | {r.us_cpu_per_core:.1f} | "
            f"{r.escaped} / {r.settled} / {r.censored} | {r.extrapolated_wall_s:.0f} s ({h:.2f} h) |"
        )
    return "\n".join(L)
