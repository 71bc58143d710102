"""``make bench-engine``: the engine's targets as ratios measured side by side in one run.

    python -m benchmarks.engine [-n N] [--repeat R] [--out DIR] [--only GROUP ...] [--update]

One process, one core, the same initial conditions for every contender,
best of ``--repeat`` timings each (the machine is shared: ratios, not
absolute times, are the result). Rows:

* **alternated** — CPU time in one process, the contenders run in turn in every
  round (``--repeat`` rounds; a ratio is the median of the rounds' ratios):
  the minimal driver (below), ``run_chunk`` bare on the same ICs (E = 0.27,
  target ≤ 1.05), and on the dissipative scene (E0 = 0.3, γ = 0.01) bare,
  recording (target ≤ 1.5), first section only, and a noise scene;
  ``--only alternated`` runs these rows alone;
* **yardstick** — a minimal refill-in-callback driver (heyoka batch, one
  escape event whose callback records the time and loads the next initial
  condition, the t_max bound, nothing else), at heyoka's recommended batch
  size; the engine's bare conservative scene against it (target ≤ 1, aim 0.8);
* **dissipative** — E0 = 0.3, γ = 0.01 against the conservative scene at
  E = 0.3 on the same ICs (target ≤ 1.6), with steps per orbit for both, so
  what the physics costs (longer lives) is told apart from overhead;
* **loose tolerance** — the engine at tol 1e-9 against numba DOP853 at tol
  1e-7 (``make bench``'s peer), conservative and dissipative (target ≥ 2×);
* **recording** — energy snapshots every 0.5 to t = 200 plus the first
  section crossing after t = 17 (E0 = 0.3, γ = 0.01) against the same scene
  bare (target ≤ 2), and the marginal cost per recorded row (target ≤ 2 µs);
* a cProfile split of the recording scene: time inside heyoka's compiled
  propagation against Python callbacks and bookkeeping;
* **whole process** — ``hhscatter simulate --energy 0.27 -n N --workers 1``
  (ICs sampled, Parquet parts written) against the minimal driver run as a
  whole process (the same ICs, the yardstick, one Parquet table of t_end;
  ``python -m benchmarks.engine --driver N SEED OUT``), in CPU time, the two
  run alternately ``--repeat`` times, the median of the pairs' ratios (target
  ≤ 1.15). ``--only whole`` (or ``recording``) runs those rows alone; ``--only`` takes several groups
  (``--only alternated recording``), and ``--update`` refreshes their rows in an existing ``engine.csv``;
* **tangent** — the tangent dynamics (``tangent = true``: u and Λ integrated with every orbit) against the
  same scene bare on the same ICs, conservative (E = 0.27) and dissipative (E0 = 0.3, γ = 0.01), alternated
  in CPU time: CPU per orbit, steps per orbit and CPU per step; ``--only tangent`` runs these rows alone;
* **saddle** — the CPU of one point of study saddle per estimator, at the precision it reaches there
  (Hénon–Heiles E = 1.8 E_c, disk r < r_s/2, t_max 200, the study's rules, N orbits up to 2·10⁴): the saddle
  points (main run with every section crossing, κ, the sprinkler selection), λ̄ with its 1/T convergence (the
  tangent run of the selected orbits and both estimators), d₁ of the section points (nearest-neighbour distances,
  floor extent/128, bootstrap over orbits), d₁ on lines (8 lines × 50 000 initial conditions run to 3 e-folds
  after t_min = 6/κ, the estimator with each line a block, and its bands of scales) and d₀ (the lines run,
  7 ε × 4000 pairs, and the fit); each row the integration's CPU plus the estimator's, the precision in its
  note. ``--only saddle`` runs these rows alone.

Writes ``benchmarks/out/engine/<full|quick>/engine.csv`` and ``engine_summary.md``
(``make docs-assets`` copies them to the benchmarks page). Not a
test: numbers vary with the machine; the ratios are what is reported.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks import peers
from benchmarks.config import out_dir
from hhscatter.integrate.engine import run_chunk
from hhscatter.integrate.events import HAMILTON_ONLY, system
from hhscatter.integrate.integrators import build_escape_only_batch
from hhscatter.integrate.plan import plan_of
from hhscatter.model import HenonHeiles

RECORD_SNAPSHOTS = tuple(float(t) for t in np.arange(0.0, 200.0 + 1e-9, 0.5))


def yardstick(ics, *, r_esc=1.03, t_max=5000.0, tol=1e-15, batch_size=None):
    """yardstick(ics, ...) -> escape times: the minimal refill-in-callback driver (no sections,
    snapshots, reruns or bookkeeping beyond recording the time and loading the next orbit).

    Its event is built from the engine's declaration (:mod:`hhscatter.integrate.events`) so that both
    integrate the same escape event; only the driver differs. It censors with a propagation bound (lane
    start + t_max), as a minimal driver would: the engine's orbit clock, which makes its tables independent
    of the chunk size, is its own cost (one more state, one more event).
    """
    import heyoka as hy  # deferred: heyoka loads on first use

    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    B = int(batch_size or hy.recommended_simd_size())
    sc = Scene(energy=0.3, n=1, r_esc=r_esc, t_max=t_max, tol=tol)
    state = {}

    class Cb:
        def __init__(self, spec=None):
            pass

        def __call__(self, ta, d, lane):
            return state["on_escape"](lane)

    ta = build_escape_only_batch(plan_of(sc), B, Cb(), tol=tol)  # x, y, px, py and the escape event alone
    ics_l = np.ascontiguousarray(ics, dtype=float).tolist()
    n = len(ics_l)
    t_end = np.full(n, t_max)
    orbit = [-1] * B
    t0 = [0.0] * B
    nxt = [0]
    st = ta.state
    hi = ta.dtime[0]

    def load(lane):
        k = nxt[0]
        if k >= n:
            orbit[lane] = -1
            return False
        nxt[0] = k + 1
        orbit[lane] = k
        st[:, lane] = ics_l[k]
        t0[lane] = hi[lane]
        ta.reset_cooldowns(lane)
        return True

    def on_escape(lane):
        t_end[orbit[lane]] = hi[lane] - t0[lane]
        return load(lane)

    state["on_escape"] = on_escape
    for lane in range(B):
        load(lane)
    tf = np.zeros(B)
    while any(k >= 0 for k in orbit):
        for lane in range(B):
            # the bound of the orbit in the lane now (a lane refilled in a callback stopped at its previous
            # orbit's bound: a stale one, which once censored ~1 orbit in 500 early and made the driver cheaper)
            if orbit[lane] >= 0 and hi[lane] >= t0[lane] + t_max:
                load(lane)  # reached t_max: censored
            tf[lane] = t0[lane] + t_max if orbit[lane] >= 0 else hi[lane]
        if all(k < 0 for k in orbit):
            break
        ta.propagate_until(tf)
    state.clear()  # break the cycle integrator → callback → closure → integrator
    return t_end


def design_choices(batch_size=8, epochs=400, epoch=8.0):
    """design_choices() -> {name: ns per lane-step}: what each way of recording costs in heyoka.

    Trapped orbits (E = 0.12, no event), ``epochs`` calls of one epoch each, as
    the epoch scheduler makes them: ``propagate_until`` (no recording),
    ``propagate_grid`` with 2 and 17 points per epoch (what snapshots every 0.5
    cost), a Python step callback copying the Taylor coefficients (the
    alternative to a grid), and ``c_output=True`` (continuous output: each call
    compiles its evaluator); ``c_output long`` is one call as long as all the
    epochs (that compilation spread over them: what storing the coefficients
    costs per lane-step). The engine uses ``propagate_grid`` for snapshot scenes
    and ``propagate_until`` otherwise.
    """
    import heyoka as hy  # deferred: heyoka loads on first use

    from hhscatter.scene.ics import section_velocities  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    m = HenonHeiles()
    rng = np.random.default_rng(7)
    r = 0.3 * np.sqrt(rng.random(batch_size))
    phi = 2 * np.pi * rng.random(batch_size)
    x, y = r * np.cos(phi), r * np.sin(phi)
    px, py = section_velocities(m, x, y, 0.12)
    st0 = np.vstack([x, y, px, py])
    sc = Scene(energy=0.3, n=1)

    sys = system(sc, HAMILTON_ONLY)
    zeros = np.zeros(batch_size)
    g2 = np.repeat(np.array([0.0, epoch])[:, None], batch_size, axis=1)
    g17 = np.repeat(np.linspace(0.0, epoch, 17)[:, None], batch_size, axis=1)

    def run(kind):
        ta = hy.taylor_adaptive_batch(sys, st0.copy(), tol=1e-15)
        tc = ta.tc
        buf = []

        def cb(ta_):
            buf.append(tc.copy())
            return True

        steps = 0
        t0 = time.perf_counter()
        if kind == "c_output long":
            ta.propagate_until(epochs * epoch, c_output=True)
            steps = sum(int(res[3]) for res in ta.propagate_res)
            return 1e9 * (time.perf_counter() - t0) / steps
        for _ in range(epochs if kind != "c_output" else max(epochs // 20, 5)):
            ta.set_time(zeros)
            if kind == "until":
                ta.propagate_until(epoch)
            elif kind == "grid2":
                ta.propagate_grid(g2)
            elif kind == "grid17":
                ta.propagate_grid(g17)
            elif kind == "step callback":
                ta.propagate_until(epoch, callback=cb)
                buf.clear()
            else:
                ta.propagate_until(epoch, c_output=True)
            steps += sum(int(res[3]) for res in ta.propagate_res)
        return 1e9 * (time.perf_counter() - t0) / steps

    out = {}
    for kind in ("until", "grid2", "grid17", "step callback", "c_output", "c_output long"):
        run(kind)  # compile outside the measurement
        out[kind] = min(run(kind) for _ in range(2))
    return out


def _best(fn, repeat):
    fn()  # JIT compilation and caches outside the measurement
    best = np.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _engine(scene, ics, **kw):
    return lambda: run_chunk(scene, ics, np.arange(len(ics)), count_steps=True, **kw)


def driver(n, seed, out, ics_path=None) -> None:
    """driver(n, seed, out, ics_path=None) -> None: the minimal driver as a whole process's work: sample the
    ICs of ``hhscatter simulate --energy 0.27 -n n --seed seed`` (its defaults: r_esc, t_max, tol), or read
    them from the Parquet table ``ics_path`` (columns x, y, px, py: what ``simulate --ics`` reads), integrate
    them with :func:`yardstick` and write one Parquet table (traj_id, t_end) to ``out``."""
    import pyarrow as pa  # deferred: pyarrow loads on first use
    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    from hhscatter.scene.ics import read_ics_table, region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    sc = Scene(energy=0.27, n=n, seed=seed)
    if ics_path is None:
        ics = region_ics(sc, 0, n)
    else:
        ics = read_ics_table(ics_path)[0]  # the reader simulate --ics uses (pyarrow, no pandas)
    t_end = yardstick(ics, r_esc=sc.r_esc, t_max=sc.t_max, tol=sc.tol)
    pq.write_table(pa.table({"traj_id": np.arange(len(ics)), "t_end": t_end}), out, compression="zstd")


def _child_cpu(cmd) -> float:
    """CPU seconds (user + system) of the process ``cmd`` run to its end (its children included)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _whole_rows(row, n, rep):
    """The whole ``hhscatter simulate`` process against the minimal driver's, in CPU time (the machine may be
    shared: CPU time moves less with the load than wall time), run alternately (driver, simulate, driver, ...)
    ``rep`` times; the ratio is the median of the ratios of each pair. With the ICs sampled (``--energy 0.27 -n
    n``) and with the same ICs read from a Parquet table (``--ics``; the driver reads that table too)."""
    import pyarrow as pa  # deferred: pyarrow loads on first use
    import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    py = [sys.executable]
    with tempfile.TemporaryDirectory(prefix="hhscatter-bench-") as tmp:
        ics = region_ics(Scene(energy=0.27, n=n, seed=1), 0, n)
        table = f"{tmp}/ics.parquet"
        pq.write_table(pa.table({c: ics[:, i] for i, c in enumerate(("x", "y", "px", "py"))}), table)
        sim = py + [
            "-m",
            "hhscatter",
            "simulate",
            "--workers",
            "1",
            "--out",
            f"{tmp}/sim",
            "--overwrite",
            "--no-progress",
        ]
        drv = py + ["-m", "benchmarks.engine", "--driver", str(n), "1", f"{tmp}/driver.parquet"]
        variants = {
            "ICs sampled": {"simulate": sim + ["--energy", "0.27", "-n", str(n), "--seed", "1"], "driver": drv},
            "IC table": {"simulate": sim + ["--ics", table, "--gamma", "0"], "driver": drv + [table]},
        }
        for label, cmds in variants.items():
            cpu = {"driver": [], "simulate": []}
            for _ in range(rep):
                for k in ("driver", "simulate"):
                    cpu[k].append(_child_cpu(cmds[k]))
            ratios = np.array(cpu["simulate"]) / np.array(cpu["driver"])
            row(
                "whole process",
                f"{label}: minimal driver, CPU s (median; one Parquet table)",
                np.median(cpu["driver"]),
                "",
            )
            row(
                "whole process",
                f"{label}: hhscatter simulate --workers 1, CPU s (median)",
                np.median(cpu["simulate"]),
                "",
            )
            row(
                "whole process",
                f"{label}: simulate / minimal driver, CPU",
                float(np.median(ratios)),
                "≤ 1.15",
                f"E = 0.27, N = {n}, imports and JIT included; median of {rep} alternated pairs "
                f"({ratios.min():.2f}-{ratios.max():.2f})",
            )


def main(argv=None):
    if argv is None and sys.argv[1:2] == ["--driver"]:  # the minimal driver's process (_whole_rows)
        n, seed, out = sys.argv[2:5]
        return driver(int(n), int(seed), out, *sys.argv[5:6])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=100_000, help="orbits per measurement (default 1e5)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument(
        "--whole-n",
        type=int,
        default=1_000_000,
        help="orbits of the whole-process rows (default 1e6, the whole-process target's N)",
    )
    ap.add_argument(
        "--out", default=None, help="output folder (default benchmarks/out/engine/full, or .../quick for N < 1e5)"
    )
    ap.add_argument(
        "--only",
        choices=("whole", "recording", "alternated", "tangent", "saddle"),
        nargs="+",
        default=None,
        help="only these rows, in one run: the whole-process rows, the recording rows (and the bare row they are "
        "read with), the in-process rows alternated in CPU time, the tangent or the saddle rows",
    )
    ap.add_argument(
        "--update",
        action="store_true",
        help="with --only: replace the rows of the targets measured in the engine.csv already in the output folder "
        "and keep its other rows (the summary then tells which rows came from which run)",
    )
    a = ap.parse_args(argv)
    n, rep = a.n, a.repeat
    rows = []

    def row(target, what, value, goal, note=""):
        rows.append({"target": target, "measure": what, "value": value, "goal": goal, "note": note})
        print(f"{target:16s} {what:58s} {value:10.3f}  {goal:>8s}  {note}", flush=True)

    print(f"# hhscatter engine benchmark: N = {n} per measurement, 1 core, best of {rep}")
    if a.only:
        groups = {
            "whole": lambda: _whole_rows(row, a.whole_n, rep),
            "recording": lambda: _recording_rows(row, n, rep),
            "alternated": lambda: _alternated_rows(row, n, rep),
            "tangent": lambda: _tangent_rows(row, n, rep),
            "saddle": lambda: _saddle_rows(row, n),
        }
        for name in dict.fromkeys(a.only):
            groups[name]()
        return _write_outputs(rows, a.out, n, rep, update=a.update)
    _alternated_rows(row, n, rep)
    _bare_rows(row, n, rep)
    c3, ics3 = _dissipative_rows(row, n, rep)
    _loose_tolerance_rows(row, n, rep, c3, ics3)
    rec, icr = _recording_rows(row, n, rep)
    _profile_row(row, rec, icr)
    _design_rows(row)
    _system_rows(row, n, rep)
    _tangent_rows(row, n, rep)
    _saddle_rows(row, n)
    _whole_rows(row, a.whole_n, rep)
    _write_outputs(rows, a.out, n, rep)


def _alternated_rows(row, n, rep):
    """The engine's in-process rows in CPU time, alternated: each round runs every contender once, in turn
    (minimal driver, ``run_chunk`` bare, the dissipative bare scene, recording, first section only, noise), so a
    change of the machine's load falls on all of them alike; a ratio is the median over the rounds of the ratio
    within a round. The driver and the bare engine integrate the same conservative ICs (E = 0.27, r_esc 1.03);
    recording and first section are read against the dissipative bare scene on the same ICs (E0 = 0.3, γ = 0.01)."""
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.noise import Noise  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene, SectionWindow  # deferred: pydantic loads on first use

    cons = Scene(energy=0.27, n=n, seed=1, r_esc=1.03)
    ics = region_ics(cons, 0, n)
    m = min(n, 20_000)
    diss = Scene(energy=0.3, gamma=0.01, n=m, seed=3, r_esc=1.03)
    icr = region_ics(diss, 0, m)
    rec = diss.replace(snapshots=RECORD_SNAPSHOTS, sections=SectionWindow(t_from=17.0, first_only=True))
    sec = diss.replace(sections=SectionWindow(t_from=17.0, first_only=True))
    k = min(n, 2_000)
    noisy = Scene(energy=0.3, n=k, seed=4, r_esc=1.03, t_max=200.0, noise=Noise(sigma=0.01))
    icn = region_ics(noisy, 0, k)
    contenders = {
        "driver": (lambda: yardstick(ics), n),
        "bare": (_engine(cons, ics), n),
        "dissipative bare": (_engine(diss, icr), m),
        "recording": (_engine(rec, icr), m),
        "first section": (_engine(sec, icr), m),
        "noise": (_engine(noisy, icn), k),
    }
    for fn, _ in contenders.values():
        fn()  # JIT compilation and caches outside the measurement
    cpu = {name: [] for name in contenders}
    for _ in range(rep):
        for name, (fn, _) in contenders.items():
            t0 = time.process_time()
            fn()
            cpu[name].append(time.process_time() - t0)
    cpu = {name: np.array(v) for name, v in cpu.items()}

    def ratio(a, b):
        r = (cpu[a] / contenders[a][1]) / (cpu[b] / contenders[b][1])
        return float(np.median(r)), f"median of {rep} rounds ({r.min():.2f}-{r.max():.2f})"

    for name, (_, count) in contenders.items():
        row("alternated", f"{name}: CPU µs/orbit (median)", 1e6 * float(np.median(cpu[name])) / count, "")
    row(
        "alternated",
        "run_chunk bare / minimal driver, CPU",
        *ratio("bare", "driver")[:1],
        "≤ 1.05",
        ratio("bare", "driver")[1] + f"; E = 0.27, N = {n}",
    )
    for name, goal in (("recording", "≤ 1.5"), ("first section", ""), ("noise", "")):
        base = "dissipative bare" if name != "noise" else "driver"
        v, note = ratio(name, base)
        row("alternated", f"{name} / {base}, CPU per orbit", v, goal, note)


def _tangent_rows(row, n, rep):
    """The tangent dynamics against the same scene bare on the same ICs (conservative E = 0.27, r_esc 1.03;
    dissipative E0 = 0.3, γ = 0.01), alternated in CPU time (each round runs the four once, in turn): CPU per
    orbit, steps per orbit, and their ratios (per orbit and per step)."""
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    m = min(n, 20_000)
    scenes = {
        "conservative": Scene(energy=0.27, n=m, seed=1, r_esc=1.03),
        "dissipative": Scene(energy=0.3, gamma=0.01, n=m, seed=3, r_esc=1.03),
    }
    contenders, steps = {}, {}
    for kind, sc in scenes.items():
        ics = region_ics(sc, 0, m)
        for tangent in (False, True):
            contenders[(kind, tangent)] = _engine(sc.replace(tangent=tangent), ics)
    for key, fn in contenders.items():
        steps[key] = fn().n_steps  # JIT compilation and caches outside the measurement
    cpu = {key: [] for key in contenders}
    for _ in range(rep):
        for key, fn in contenders.items():
            t0 = time.process_time()
            fn()
            cpu[key].append(time.process_time() - t0)
    for kind in scenes:
        bare, tan = np.array(cpu[(kind, False)]), np.array(cpu[(kind, True)])
        r = tan / bare
        note = f"median of {rep} rounds ({r.min():.2f}-{r.max():.2f}); N = {m}"
        s_b, s_t = steps[(kind, False)], steps[(kind, True)]
        row("tangent", f"{kind} bare: CPU µs/orbit (median)", 1e6 * float(np.median(bare)) / m, "")
        row("tangent", f"{kind} tangent: CPU µs/orbit (median)", 1e6 * float(np.median(tan)) / m, "")
        row("tangent", f"{kind} tangent / bare, CPU per orbit", float(np.median(r)), "", note)
        row("tangent", f"{kind} tangent / bare, steps per orbit", s_t / s_b, "", f"{s_b / m:.1f} -> {s_t / m:.1f}")
        row("tangent", f"{kind} tangent / bare, CPU per step", float(np.median(r)) * s_b / s_t, "")


def _cpu(fn):
    """(CPU seconds, result) of one call."""
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def _saddle_rows(row, n):
    """CPU per point of each estimator of study saddle at the precision it reaches (module notes): one point,
    Hénon–Heiles E = 1.8 E_c, the study's quick rules (t_min = 4/κ, window 0.4–0.6, d₁ from extent/128 to
    extent/8, k_max 16, n_boot 100; d₁ on lines: 8 × 50 000 ICs, t_min = 6/κ, floor 10⁻⁴ of a line's extent, its
    decades of scales; d₀ over ε = 1e-2 … 1e-8, 4000 pairs each, fitted where ≥ 10 pairs are uncertain). Each
    estimator measured once after a warm-up run of the engine (JIT outside the measurement)."""
    import pandas as pd  # deferred: pandas loads on first use

    from hhscatter.analysis.geometry.saddle import (  # deferred: the estimators load on first use
        dimension_from_uncertainty,
        information_dimension_neighbours,
        lyapunov_convergence,
        mean_lyapunov,
        neighbour_scale_bands,
        saddle_points,
    )
    from hhscatter.analysis.geometry.uncertainty import uncertainty_fraction  # deferred: as above
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes  # deferred: as above
    from hhscatter.outcomes import LEAVING_OUTCOMES, OUTCOMES  # deferred: as above
    from hhscatter.scene.ics import (  # deferred: pydantic loads on first use
        chord_lines,
        perturbed_on_section,
        region_ics,
    )
    from hhscatter.scene.scene import Scene, SectionWindow  # deferred: pydantic loads on first use

    m = min(n, 20_000)
    probe = Scene(energy=0.3, n=m, seed=5252, t_max=200.0)
    sc = probe.replace(radius=0.5 * probe.model.saddle_radius, sections=SectionWindow(t_from=0.0))
    ics = region_ics(sc, 0, m)
    run_chunk(sc, ics[:200], np.arange(200))  # JIT compilation outside the measurement

    def frame(cols):
        df = pd.DataFrame({k: np.asarray(v) for k, v in cols.items()})
        if "outcome" in df and df["outcome"].dtype.kind in "iu":
            df["outcome"] = np.asarray(OUTCOMES)[df["outcome"].to_numpy()]
        return df

    # saddle points: the main run, κ, the selection
    t_run, res = _cpu(lambda: run_chunk(sc, ics, np.arange(m)))
    lt, sec = frame(res.lifetimes), frame(res.sections)
    left = lt[lt["outcome"].isin(LEAVING_OUTCOMES)]
    t_k, k = _cpu(lambda: escape_rate_from_lifetimes(left, detect_tail=False))
    t_min = 4.0 / k.kappa
    t_sp, sp = _cpu(lambda: saddle_points(lt, sec, t_min=t_min, window=(0.4, 0.6), columns=["x", "y"]))
    row("saddle", "saddle points: CPU s per point", t_run + t_k + t_sp, "",
        f"main run {t_run:.1f} s + κ {t_k:.2f} s + selection {t_sp:.2f} s; N = {m}, κ = {k.kappa:.4f} ± "
        f"{k.kappa_err:.4f}, {sp.n_orbits} orbits, {sp.n_points} points")  # fmt: skip
    # λ̄ and its convergence: the tangent run of the selected orbits
    sel = lt[lt["outcome"].isin(LEAVING_OUTCOMES) & (lt["t_end"] >= t_min)]
    tics = sel[["x0", "y0", "px0", "py0"]].to_numpy()
    tsc = sc.replace(n=len(tics), sections=None, tangent=True)
    run_chunk(tsc, tics[:50], np.arange(min(50, len(tics))))  # JIT of the tangent system
    t_tan, tres = _cpu(lambda: run_chunk(tsc, tics, np.arange(len(tics))))
    tl = frame(tres.lifetimes)
    tl = tl[tl["outcome"].isin(LEAVING_OUTCOMES) & (tl["t_end"] >= t_min)]
    L, T = tl["log_stretch"].to_numpy(), tl["t_end"].to_numpy()
    t_mean, lam = _cpu(lambda: mean_lyapunov(L, T, n_boot=100, seed=0))
    t_conv, conv = _cpu(lambda: lyapunov_convergence(L, T, n_bins=5, n_boot=100, seed=0))
    row("saddle", "λ̄ with its convergence: CPU s per point", t_tan + t_mean + t_conv, "",
        f"tangent run {t_tan:.1f} s ({len(tics)} orbits) + estimators {t_mean + t_conv:.2f} s; λ̄ = "
        f"{lam.value:.4f} ± {lam.err:.4f}, λ∞ = {conv.extrapolated:.3f} ± {conv.extrapolated_err:.3f}")  # fmt: skip
    # d₁: nearest-neighbour distances with the bootstrap over orbits
    P = sp.points[["x", "y"]].to_numpy()
    t_d1, d1 = _cpu(lambda: information_dimension_neighbours(P, groups=sp.points["traj_id"].to_numpy(), k_max=16,
                                                             floor=1 / 128, n_boot=100, seed=0))  # fmt: skip
    row("saddle", "d₁ (section): CPU s per point", t_d1, "",
        f"nearest-neighbour distances of the saddle points above (their run counted there); D₁ = {d1.value:.3f} ± "
        f"{d1.err:.3f}")  # fmt: skip
    # d₁ on lines: the dense lines' run, the survivors after 6/κ, the estimator with each line a block and its bands
    st, on_line = chord_lines(sc.model, sc.energy, float(sc.radius), 8, 50_000, np.random.default_rng([5252, 52]))
    dsc = sc.replace(n=len(st), sections=None, t_max=min(sc.t_max, 9.0 / k.kappa))
    t_dl, dres = _cpu(lambda: run_chunk(dsc, st, np.arange(len(st))))
    dl = frame(dres.lifetimes)
    keep = dl["outcome"].isin(LEAVING_OUTCOMES).to_numpy() & (dl["t_end"].to_numpy() >= 6.0 / k.kappa)
    xs, blocks = st[keep, 0], on_line[keep]
    t_l1, l1 = _cpu(lambda: information_dimension_neighbours(xs, blocks=blocks, k_max=16, floor=1e-4, n_boot=100,
                                                             seed=0))  # fmt: skip
    decades = [(1e-4, 1e-3), (1e-3, 1e-2), (1e-2, 0.125)]
    t_b, bands = _cpu(lambda: neighbour_scale_bands(xs, blocks=blocks, bands=decades, k_max=16, n_boot=100, seed=0))
    low = bands.iloc[0]
    row("saddle", "d₁ on lines (with its bands): CPU s per point", t_dl + t_l1 + t_b, "",
        f"lines run {t_dl:.1f} s ({len(st)} orbits) + estimator {t_l1:.2f} s + bands {t_b:.2f} s; d₁ = "
        f"{l1.value:.3f} ± {l1.err:.3f} ({int(keep.sum())} survivors), over 10⁻⁴–10⁻³ of a line's extent "
        f"{low['value']:.3f} ± {low['err']:.3f}")  # fmt: skip
    # d₀: the lines run and the fit
    eps, n_pairs, refs, moved = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8], 4000, [], []
    for i, e in enumerate(eps):
        ref = region_ics(sc.replace(seed=5252 * 100 + 1 + i, n=n_pairs), 0, n_pairs)
        mv, ok = perturbed_on_section(sc.model, ref, sc.energy, dx=e)
        refs.append(ref[ok])
        moved.append(mv[ok])
    lines = np.concatenate([x for pair in zip(refs, moved) for x in pair])
    lsc = sc.replace(n=len(lines), sections=None)
    t_lines, lres = _cpu(lambda: run_chunk(lsc, lines, np.arange(len(lines))))

    def fit():
        out = lres.lifetimes["outcome"]
        code = np.where(np.asarray(out) == OUTCOMES.index("escaped"), lres.lifetimes["exit_channel"], -1)
        rows, at = [], 0
        for e, r in zip(eps, refs):
            u = uncertainty_fraction(code[at : at + len(r)], code[at + len(r) : at + 2 * len(r)], outside=-1)
            rows.append((e, u.f, u.k, u.n))
            at += 2 * len(r)
        e_, f_, k_, n_ = (np.array(c) for c in zip(*rows))
        ok = (k_ >= 10) & (k_ < n_)
        return dimension_from_uncertainty(e_, f_, n_, eps_range=(e_[ok].min(), e_[ok].max()))

    t_fit, d0 = _cpu(fit)
    row("saddle", "d₀ = 1 − α (lines): CPU s per point", t_lines + t_fit, "",
        f"lines run {t_lines:.1f} s ({len(lines)} orbits) + fit {t_fit:.2f} s; d₀ = {d0.value:.3f} ± {d0.err:.3f} "
        f"over ε {d0.eps_range[0]:.0e}-{d0.eps_range[1]:.0e}")  # fmt: skip


def _bare_rows(row, n, rep):
    """The bare conservative scene against the yardstick driver (µs/orbit and their ratio)."""
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    # -- bare conservative vs the yardstick ----------------------------------------------
    cons = Scene(energy=0.27, n=n, seed=1, r_esc=1.03)
    ics = region_ics(cons, 0, n)
    t_y, ty = _best(lambda: yardstick(ics), rep)
    t_e, res = _best(_engine(cons, ics), rep)
    lt = res.lifetimes
    agree = np.mean(np.abs(lt["t_end"] - ty) <= 1e-9 * np.maximum(1.0, ty))
    row("bare", "yardstick µs/orbit (recommended batch size)", 1e6 * t_y / n, "")
    row("bare", "engine µs/orbit", 1e6 * t_e / n, "")
    row("bare", "engine / yardstick", t_e / t_y, "≤ 1 (0.8)", f"same t_end (1e-9) on {100 * agree:.1f} % of orbits")


def _system_rows(row, n, rep):
    """Systems as data: Hénon–Heiles declared as an expression against the built-in on the same ICs
    (target ≤ 1.05: a declared potential costs no more per step), and ns per lane-step of the other built-ins."""
    from hhscatter.model.spec import system_from_spec  # deferred: like the scene imports beside it
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    m = min(n, 50_000)
    built = Scene(energy=0.27, n=m, seed=1, r_esc=1.5)
    declared = built.replace(system={"potential": "0.5*(x**2 + y**2) + x**2*y - y**3/3"})
    ics = region_ics(built, 0, m)
    t_b, rb = _best(_engine(built, ics), rep)
    t_d, rd = _best(_engine(declared, ics), rep)
    same = np.mean(np.abs(rd.lifetimes["t_end"] - rb.lifetimes["t_end"]) <= 1e-9 * rb.lifetimes["t_end"])
    row("systems", "built-in Hénon–Heiles: ns/step", 1e9 * t_b / rb.n_steps, "")
    row("systems", "declared '0.5*(x**2 + y**2) + x**2*y - y**3/3': ns/step", 1e9 * t_d / rd.n_steps, "")
    row(
        "systems",
        "declared / built-in, per step",
        (t_d / rd.n_steps) / (t_b / rb.n_steps),
        "≤ 1.05",
        f"same t_end (1e-9) on {100 * same:.1f} % of orbits",
    )
    for spec in ({"name": "contopoulos"}, {"name": "n_exit", "params": {"n": 4}}, {"name": "barbanis"}):
        sc = Scene(energy=1.5 * system_from_spec(spec).critical_energy, n=min(m, 20_000), system=spec)
        t, r = _best(_engine(sc, region_ics(sc, 0, sc.n)), rep)
        row(
            "systems",
            f"{spec['name']} at 1.5 E_c: ns/step",
            1e9 * t / r.n_steps,
            "",
            f"{r.n_steps / sc.n:.1f} steps/orbit",
        )


def _dissipative_rows(row, n, rep):
    """Dissipative against conservative at E0 = 0.3 on the same ICs; returns that scene and its ICs."""
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    # -- dissipative vs conservative at the same energy -----------------------------------
    c3 = Scene(energy=0.3, n=n, seed=2, r_esc=1.03)
    d3 = c3.replace(gamma=0.01)
    ics3 = region_ics(c3, 0, n)
    t_c, rc = _best(_engine(c3, ics3), rep)
    t_d, rd = _best(_engine(d3, ics3), rep)
    sc_, sd_ = rc.n_steps / n, rd.n_steps / n
    row("dissipative", "conservative E = 0.3: µs/orbit", 1e6 * t_c / n, "", f"{sc_:.1f} steps/orbit")
    row("dissipative", "dissipative E0 = 0.3, γ = 0.01: µs/orbit", 1e6 * t_d / n, "", f"{sd_:.1f} steps/orbit")
    row(
        "dissipative",
        "dissipative / conservative",
        t_d / t_c,
        "≤ 1.6",
        f"per step: {(t_d / rd.n_steps) / (t_c / rc.n_steps):.2f}×",
    )
    return c3, ics3


def _loose_tolerance_rows(row, n, rep, c3, ics3):
    """The engine at tol 1e-9 against numba DOP853 at 1e-7, conservative and dissipative."""
    # -- loose tolerance vs numba DOP853 ----------------------------------------------------
    m = min(n, 20_000)
    for label, gamma in (("conservative", 0.0), ("dissipative", 0.01)):
        sc = c3.replace(gamma=gamma, tol=1e-9, n=m)
        t_l, _ = _best(_engine(sc, ics3[:m]), rep)
        t_p, _ = _best(lambda g=gamma: peers.dop853(ics3[:m], 1e-7, gamma=g, r_esc=1.03), rep)
        row(
            "loose tol",
            f"{label}: numba DOP853 (1e-7) / engine (1e-9)",
            t_p / t_l,
            "≥ 2",
            f"engine {1e6 * t_l / m:.2f}, DOP853 {1e6 * t_p / m:.2f} µs/orbit",
        )


def _recording_rows(row, n, rep):
    """Snapshots and the first section crossing against the bare scene; returns the recording scene and ICs."""
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene, SectionWindow  # deferred: pydantic loads on first use

    # -- recording scene ---------------------------------------------------------------------
    m = min(n, 20_000)
    bare = Scene(energy=0.3, gamma=0.01, n=m, seed=3, r_esc=1.03)
    rec = bare.replace(snapshots=RECORD_SNAPSHOTS, sections=SectionWindow(t_from=17.0, first_only=True))
    icr = region_ics(bare, 0, m)
    t_b, rb = _best(_engine(bare, icr), rep)
    t_r, rr = _best(_engine(rec, icr), rep)
    n_rows = len(rr.snapshots["t"]) + len(rr.sections["t"])
    row("recording", "bare µs/orbit", 1e6 * t_b / m, "", f"{rb.n_steps / m:.1f} steps/orbit")
    row(
        "recording",
        "recording µs/orbit",
        1e6 * t_r / m,
        "",
        f"{rr.n_steps / m:.1f} steps/orbit, {n_rows / m:.1f} rows/orbit",
    )
    row("recording", "recording / bare", t_r / t_b, "≤ 2")
    row("recording", "marginal µs per recorded row", 1e6 * (t_r - t_b) / max(n_rows, 1), "≤ 2")
    only_snap = bare.replace(snapshots=RECORD_SNAPSHOTS)
    t_s, rs = _best(_engine(only_snap, icr), rep)
    row("recording", "snapshots only / bare", t_s / t_b, "", "epoch scheduler: propagate_grid")
    only_sec = bare.replace(sections=SectionWindow(t_from=17.0, first_only=True))
    t_x, _ = _best(_engine(only_sec, icr), rep)
    row("recording", "first section after t = 17 only / bare", t_x / t_b, "", "gated section event + clock")
    return rec, icr


def _profile_row(row, rec, icr):
    """cProfile of the recording scene: the share of time inside heyoka's compiled propagation."""
    # -- where the recording scene's time goes --------------------------------------------
    prof = cProfile.Profile()
    fn = _engine(rec, icr)
    prof.enable()
    fn()
    prof.disable()
    stats = pstats.Stats(prof).stats
    total = sum(v[2] for v in stats.values())
    inside = sum(
        v[2]
        for k, v in stats.items()
        if k[2] in ("propagate_grid", "propagate_until") or "propagate_grid" in k[2] or "propagate_until" in k[2]
    )
    row(
        "profile",
        "recording: share inside heyoka's compiled propagation",
        inside / total,
        "",
        "self time of propagate_*; the rest is Python (callbacks, epochs, numpy)",
    )


def _design_rows(row):
    """ns per lane-step of the propagation modes behind the epoch scheduler."""
    # -- the design choices behind the epoch scheduler -------------------------------------
    dc = design_choices()
    for kind, label in (
        ("until", "propagate_until (no recording)"),
        ("grid2", "propagate_grid, 2 points/epoch"),
        ("grid17", "propagate_grid, 17 points/epoch (snapshots every 0.5)"),
        ("step callback", "Python step callback copying the Taylor coefficients"),
        ("c_output", "propagate_until with c_output=True"),
        ("c_output long", "c_output=True, one call of all the epochs"),
    ):
        row("design", f"ns per lane-step: {label}", dc[kind], "", f"{dc[kind] / dc['until']:.2f}× propagate_until")


def _write_outputs(rows, out, n, rep, update=False):
    """engine.csv and engine_summary.md in ``out`` (default benchmarks/out/engine/full or quick). ``update``: the
    targets measured here replace theirs in the engine.csv already there, whose other rows are kept (targets new
    to it come first)."""
    out = Path(out) if out else out_dir("engine", "full" if n >= 100_000 else "quick")
    out.mkdir(parents=True, exist_ok=True)
    import pandas as pd  # deferred: pandas loads on first use

    df = pd.DataFrame(rows)
    header = (
        f"Engine targets, N = {n} per measurement, 1 core, best of {rep}; every ratio is measured side by side in "
        "one run."
    )
    if update and (out / "engine.csv").exists():
        old = pd.read_csv(out / "engine.csv", keep_default_na=False)
        measured = list(dict.fromkeys(df["target"]))
        parts = [df[df["target"] == t] for t in measured if t not in set(old["target"])]
        for t in dict.fromkeys(old["target"]):
            parts.append(df[df["target"] == t] if t in measured else old[old["target"] == t])
        df = pd.concat(parts, ignore_index=True)
        header = (
            "Engine targets, 1 core; every ratio is measured side by side in one run. The rows of "
            f"{', '.join(measured)} are from a run with N = {n} per measurement, {rep} rounds or best of {rep}; "
            "the other rows from an earlier run."
        )
    df.to_csv(out / "engine.csv", index=False)
    lines = ["| target | measure | value | goal | note |", "|---|---|---|---|---|"]
    lines += [f"| {r.target} | {r.measure} | {r.value:.3g} | {r.goal} | {r.note} |" for r in df.itertuples()]
    (out / "engine_summary.md").write_text(header + "\n\n" + "\n".join(lines) + "\n")
    print(f"wrote {out / 'engine.csv'} and {out / 'engine_summary.md'}")


if __name__ == "__main__":
    main()
