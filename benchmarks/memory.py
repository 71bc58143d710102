"""``make bench-memory``: peak memory of simulate + P(t) analysis as N grows.

    python -m benchmarks.memory [--n 1e5 1e6 1e7] [--energy 0.27] [--workers 1]
                                     [--chunk-size 10000] [--dir runs/bench-memory] [--keep]

For each N, two fresh processes are measured by their peak resident set size
(``ru_maxrss`` from ``wait4``; with ``--workers`` > 1 this is the largest single
process, not the sum over the pool):

* ``simulate``: ``hhscatter simulate --energy E -n N --workers W`` (disk ICs,
  γ = 0, t_max = 5000, the engine's defaults);
* ``analysis``: :func:`hhscatter.data.read.survival_arrays` (column projection:
  ``t_end`` and ``outcome`` only) → Kaplan–Meier P(t) at every event time →
  exponential fit of κ over t ∈ [5, 40] (paper Eq. eqn:kappa_hyperbolic);
* ``streamed``: :func:`hhscatter.api.stream_survival` (P(t) on a grid of
  1001 times, one part file at a time) → the same fit.

A third process that only imports the engine and integrates 64 orbits gives
the fixed cost (Python, numpy, pyarrow, heyoka/LLVM and its JIT code).
Simulation memory should not grow with N (O(chunk)); the Kaplan–Meier
analysis grows by ~140 bytes per orbit (its arrays over all event times), the
streamed one not at all. The slope per 1e6
orbits is fitted and extrapolated. The target: N = 1e7 under 2 GB.
At E = 0.27 one orbit costs ~20 µs on one core in the worst case (trapped
orbits run to t_max), so N = 1e7 is minutes to hours depending on the machine.
Not a test: numbers vary with the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

_SNIPPETS = {
    "baseline": (
        "import numpy as np; from hhscatter.scene.scene import Scene; from hhscatter.integrate.engine import run_chunk;"
        "from hhscatter.scene.ics import region_ics; import pyarrow.parquet, tqdm;"
        "s = Scene(energy={energy}, n=64); run_chunk(s, region_ics(s, 0, 64), np.arange(64))"
    ),
    "simulate": (
        "import sys; from hhscatter.cli import main;"
        "sys.exit(main(['simulate', '--energy', '{energy}', '-n', '{n}', '--seed', '1', '--workers', '{workers}',"
        "'--chunk-size', '{chunk}', '--out', '{out}', '--quiet', '--overwrite']))"
    ),
    "analysis": (
        "import json; from hhscatter.data.read import survival_arrays;"
        "from hhscatter.analysis.survival.fits import survival_curve, fit_exponential;"
        "t, obs = survival_arrays('{out}'); c = survival_curve(t, obs);"
        "f = fit_exponential(c.t, c.P, (5.0, 40.0), P_err=c.P_err);"
        "print(json.dumps({{'n': int(t.size), 'kappa': float(f.kappa), 'kappa_err': float(f.kappa_err)}}))"
    ),
    "streamed": (
        "import json, numpy as np; from hhscatter.api import stream_survival;"
        "from hhscatter.analysis.survival.fits import fit_exponential;"
        "c = stream_survival('{out}', np.linspace(0.0, 100.0, 1001));"
        "f = fit_exponential(c.t, c.P, (5.0, 40.0), P_err=c.P_err);"
        "print(json.dumps({{'kappa': float(f.kappa), 'kappa_err': float(f.kappa_err)}}))"
    ),
}


def measure(stage: str, **kw) -> dict:
    """measure(stage, **kw) -> {'peak_mb', 'wall_s', 'stdout'} of one fresh Python process."""
    code = _SNIPPETS[stage].format(**kw)
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # read the pipes before reaping: wait4 gives this child's own peak RSS (and its reaped children's)
    out, err = proc.stdout.read(), proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{stage} failed (exit {proc.returncode}):\n{err[-2000:]}")
    return {
        "peak_mb": usage.ru_maxrss / 1024.0,
        "wall_s": wall,
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "stdout": out.strip(),
    }


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m benchmarks.memory", description=__doc__.splitlines()[0])
    p.add_argument("--n", nargs="+", type=float, default=[1e5, 1e6, 1e7], help="ensemble sizes")
    p.add_argument("--energy", type=float, default=0.27)
    p.add_argument("--workers", type=int, default=1)
    p.add_argument("--chunk-size", type=int, default=10000, dest="chunk")
    p.add_argument("--dir", default="runs/bench-memory", help="where the runs and memory.json go")
    p.add_argument("--keep", action="store_true", help="keep the run directories")
    a = p.parse_args(argv)
    base = Path(a.dir)
    base.mkdir(parents=True, exist_ok=True)

    rows = []
    b = measure("baseline", energy=a.energy)
    print(f"baseline (imports + JIT + 64 orbits): peak {b['peak_mb']:.0f} MB", flush=True)
    print(
        f"{'N':>10} {'sim peak MB':>12} {'sim wall s':>10} {'sim CPU s':>10} {'µs/orbit/core':>14} "
        f"{'P(t) peak MB':>13} {'P(t) wall s':>11} {'grid P(t) MB':>13}  κ (KM)  κ (grid)",
        flush=True,
    )
    for n in (int(x) for x in a.n):
        out = base / f"E{a.energy}-N{n}"
        sim = measure("simulate", energy=a.energy, n=n, workers=a.workers, chunk=a.chunk, out=out)
        ana = measure("analysis", out=out)
        fit = json.loads(ana["stdout"].splitlines()[-1])
        st = measure("streamed", out=out)
        fit_st = json.loads(st["stdout"].splitlines()[-1])
        row = {
            "n": n,
            "sim_peak_mb": sim["peak_mb"],
            "sim_wall_s": sim["wall_s"],
            "sim_cpu_s": sim["cpu_s"],
            "us_per_orbit_core": 1e6 * sim["cpu_s"] / n,
            "analysis_peak_mb": ana["peak_mb"],
            "analysis_wall_s": ana["wall_s"],
            **fit,
            "streamed_peak_mb": st["peak_mb"],
            "streamed_wall_s": st["wall_s"],
            "streamed_kappa": fit_st["kappa"],
            "streamed_kappa_err": fit_st["kappa_err"],
        }
        rows.append(row)
        print(
            f"{n:>10} {row['sim_peak_mb']:>12.0f} {row['sim_wall_s']:>10.1f} {row['sim_cpu_s']:>10.1f} "
            f"{row['us_per_orbit_core']:>14.1f} {row['analysis_peak_mb']:>13.0f} {row['analysis_wall_s']:>11.1f}"
            f" {row['streamed_peak_mb']:>13.0f}  {fit['kappa']:.4f} ± {fit['kappa_err']:.4f}"
            f"  {fit_st['kappa']:.4f} ± {fit_st['kappa_err']:.4f}",
            flush=True,
        )
        if not a.keep:
            shutil.rmtree(out, ignore_errors=True)
    doc = {
        "energy": a.energy,
        "workers": a.workers,
        "chunk_size": a.chunk,
        "baseline_peak_mb": b["peak_mb"],
        "rows": rows,
    }
    if len(rows) >= 2:
        ns = np.array([r["n"] for r in rows], float)
        for key in ("sim_peak_mb", "analysis_peak_mb", "streamed_peak_mb"):
            slope, icept = np.polyfit(ns / 1e6, [r[key] for r in rows], 1)
            doc[f"{key}_per_1e6"] = slope
            doc[f"{key}_at_1e7"] = icept + 10 * slope
            print(f"{key}: {slope:+.1f} MB per 1e6 orbits → {icept + 10 * slope:.0f} MB extrapolated to N = 1e7")
    (base / "memory.json").write_text(json.dumps(doc, indent=2))
    print(f"wrote {base / 'memory.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
