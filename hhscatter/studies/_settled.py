"""Energies of settled orbits after they settle (raw data for ⟨E⟩(t), paper Fig. 3).

The engine stops a dissipative orbit when its energy reaches E_c inside Ω
('settled', paper App. "Escape Condition"): below E_c it can never leave,
so its fate is known.  The paper's Fig. 3 (fig:energy_decay), however,
averages the energy over *every* orbit inside Ω at time t, including those
below E_c ("after [t = 200] the only remaining orbits will be slowly
collapsing towards the origin"; the fitted ⟨E⟩(200) = 0.3 e^{−1.82} ≈ 0.05
lies far below E_c = 1/6).  This module supplies the missing part: it
re-integrates each settled orbit from its initial condition on heyoka's
scalar Taylor integrator (same equations, same tolerance) and records its
energy at the snapshot grid times after the engine's settling time, in the
``snapshots`` table schema (traj_id, t, energy).  Together with the engine's
snapshots (which hold every orbit at grid times ≤ its t_end) this gives, at
each grid time, every orbit that has not escaped.

Why re-integrate from t = 0: the lifetimes table keeps the initial state,
not the state at settling.  The re-integration is a different (scalar,
event-free) computation of the same orbit, so chaos can make it drift from
the engine's batch integration; each re-integrated orbit is therefore
checked: it must cross E = E_c (downward) inside the saddle radius, and the
settling time t_s' it finds is compared with the engine's t_s.  Orbits
that fail (none so far; see the ``n_failed`` diagnostic) are left out and
counted.

Output: ``<out>/snapshots/part-000000.parquet`` (+ more parts for large
runs) with the run's provenance and these diagnostics in the metadata, and
``<out>/continuation.json`` (summary, including the key that identifies
the inputs, so a finished continuation is not recomputed).
"""
from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

import numpy as np

CHUNK = 2000  # orbits per part file / task


def _key(scene, grid, t_settle):
    h = hashlib.sha256()
    h.update(scene.result_hash().encode())
    h.update(np.ascontiguousarray(grid, dtype=float).tobytes())
    h.update(np.ascontiguousarray(t_settle, dtype=float).tobytes())
    return h.hexdigest()


def _continue_chunk(scene_json: str, ids, ics, t_settle, grid):
    """Worker: re-integrate orbits ``ics`` and return (rows dict, diagnostics dict)."""
    import heyoka as hy

    from ..model import equations
    from ..scene import scene_from_dict

    scene = scene_from_dict(json.loads(scene_json))
    m = scene.model
    (x, y, _, _), _, H = m.expressions()
    rec = {}

    def on_closure(ta, t, d):
        if "t" not in rec:
            rec["t"] = float(t)
            ta.update_d_output(t)
            s = ta.d_output
            rec["r2"] = float(s[0] ** 2 + s[1] ** 2)

    r_far = scene.r_far if scene.r_far is not None else max(10.0 * m.saddle_radius, 2.0 * scene.r_esc)
    ta = hy.taylor_adaptive(
        equations(m, hy.par[0]),
        np.zeros(4),
        pars=[scene.gamma],
        tol=scene.tol,
        # terminal: an orbit that (wrongly) escapes in the re-integration is stopped before blow-up
        t_events=[hy.t_event(x**2 + y**2 - r_far**2, direction=hy.event_direction.positive)],
        nt_events=[hy.nt_event(H - m.critical_energy, on_closure, direction=hy.event_direction.negative)],
    )
    out_id, out_t, out_e = [], [], []
    dts, failed = [], 0
    for k in range(len(ids)):
        after = grid[grid > t_settle[k]]
        ta.state[:] = ics[k]
        ta.time = 0.0
        ta.reset_cooldowns()
        rec.clear()
        tgrid = np.concatenate([[0.0], after]) if after.size else np.array([0.0, t_settle[k] * 1.001 + 1.0])
        res = ta.propagate_grid(tgrid)
        ok = (res[0] == hy.taylor_outcome.time_limit and "t" in rec
              and rec["r2"] <= m.saddle_radius**2)
        if not ok:
            failed += 1
            continue
        dts.append(rec["t"] - t_settle[k])
        if after.size:
            st = res[-1][1:]
            out_id.append(np.full(after.size, ids[k], dtype=np.int64))
            out_t.append(after)
            out_e.append(m.energy(st[:, 0], st[:, 1], st[:, 2], st[:, 3]))
    cat = (lambda a, dt: np.concatenate(a) if a else np.empty(0, dtype=dt))
    rows = {"traj_id": cat(out_id, np.int64), "t": cat(out_t, float), "energy": cat(out_e, float)}
    diag = {"n": len(ids), "n_failed": failed, "dt_settle": np.asarray(dts, dtype=float)}
    return rows, diag


def continue_settled(scene, lifetimes, grid, out, *, workers=None, progress=True) -> dict:
    """continue_settled(scene, lifetimes, grid, out, workers=None) -> summary dict.

    Energies at the grid times t > t_s of every orbit of ``lifetimes`` (the
    engine's table of ``scene``) whose outcome is 'settled' (t_s = its
    t_end), written as a ``snapshots`` table under ``out``.  ``grid``: the
    snapshot times (time units, increasing).  Summary keys: n_settled,
    n_failed (re-integration did not settle inside Ω), rows,
    dt_settle_max_abs / dt_settle_median_abs (|t_s' − t_s| between the
    re-integration and the engine), cpu_seconds.  Recomputes only when the
    inputs (scene, grid, settling times) changed.
    """
    from ..tables import provenance, to_arrow, write_part
    from . import write_json_atomic

    if not scene.gamma > 0:
        raise ValueError(f"continue_settled needs a dissipative scene (gamma > 0), got gamma = {scene.gamma}")
    out = Path(out)
    grid = np.asarray(grid, dtype=float)
    st = lifetimes[lifetimes["outcome"] == "settled"].sort_values("traj_id")
    ids = st["traj_id"].to_numpy(np.int64)
    ics = st[["x0", "y0", "px0", "py0"]].to_numpy(float)
    t_settle = st["t_end"].to_numpy(float)
    key = _key(scene, grid, t_settle)
    summary_path = out / "continuation.json"
    if summary_path.exists():
        old = json.loads(summary_path.read_text())
        if old.get("key") == key:
            return old
    snap_dir = out / "snapshots"
    if snap_dir.exists():
        for p in snap_dir.glob("part-*.parquet"):
            p.unlink()
    out.mkdir(parents=True, exist_ok=True)

    chunks = [(i, s, min(s + CHUNK, len(ids))) for i, s in enumerate(range(0, len(ids), CHUNK))]
    scene_json = scene.to_json()
    t0 = time.perf_counter()
    cpu = 0.0
    results = {}
    args = [(scene_json, ids[s:e], ics[s:e], t_settle[s:e], grid) for _, s, e in chunks]
    if (workers or 1) == 1 or len(chunks) <= 1:
        for (c, _, _), a in zip(chunks, args):
            c0 = time.perf_counter()
            results[c] = _continue_chunk(*a)
            cpu += time.perf_counter() - c0
    else:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(max_workers=min(workers, len(chunks)), mp_context=mp.get_context("spawn")) as pool:
            futs = {c: pool.submit(_continue_chunk, *a) for (c, _, _), a in zip(chunks, args)}
            for c, f in futs.items():
                results[c] = f.result()
        cpu = (time.perf_counter() - t0) * min(workers, len(chunks))
    n_failed, rows_total, dts = 0, 0, []
    meta_base = {"scene": json.loads(scene_json), "scene_hash": scene.result_hash(), "continuation_key": key,
                 "what": "energies of settled orbits after settling (hhscatter.studies._settled)", **provenance()}
    for c, _, _ in chunks or [(0, 0, 0)]:
        rows, diag = results.get(c, ({"traj_id": np.empty(0, np.int64), "t": np.empty(0), "energy": np.empty(0)},
                                     {"n_failed": 0, "dt_settle": np.empty(0)}))
        table = to_arrow("snapshots", rows)
        write_part(snap_dir / f"part-{c:06d}.parquet", table, {**meta_base, "chunk": c, "rows": table.num_rows})
        n_failed += diag["n_failed"]
        rows_total += table.num_rows
        dts.append(diag["dt_settle"])
    dts = np.abs(np.concatenate(dts)) if dts else np.empty(0)
    summary = {
        "key": key,
        "n_settled": len(ids),
        "n_failed": int(n_failed),
        "rows": int(rows_total),
        "dt_settle_max_abs": float(dts.max()) if dts.size else None,
        "dt_settle_median_abs": float(np.median(dts)) if dts.size else None,
        "cpu_seconds": float(cpu),
        "wall_seconds": float(time.perf_counter() - t0),
    }
    write_json_atomic(summary_path, summary)
    if progress:
        print(f"  continued {summary['n_settled']} settled orbits ({summary['n_failed']} failed, "
              f"{rows_total} rows, max |Δt_s| = {summary['dt_settle_max_abs']}) in {summary['wall_seconds']:.1f} s",
              flush=True)
    return summary
