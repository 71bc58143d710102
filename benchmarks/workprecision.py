"""Work–precision of hhscatter's engine against the paper's integrators (``make bench``).

Two scenes, the same initial conditions for every method (disk ICs of
:mod:`hhscatter.scene.ics`, fixed seed) and the same escape rule:

* conservative, E = 0.27 (paper Fig. 2a): escape at r = r_esc;
* dissipative, E0 = 0.3, γ = 0.01 (paper Figs. 3–4): closure at E_c, escape
  time = last outward r_esc crossing.

Methods (see :mod:`benchmarks.peers`): the engine at several tolerances
and batch sizes; KahanLi8 (the paper's conservative integrator) at fixed dt
with escape checked at step ends and root-found; DOP853 compiled with numba
at several tolerances; SciPy's ``solve_ivp`` DOP853 on a subset.
Reference: heyoka in long double (:mod:`benchmarks.reference`), itself
checked against real128 on a subset.

Timing: each method runs once on 8 orbits (JIT compilation), then
``repeats`` times on all orbits; in each repeat the methods run one after the
other in a shuffled order, so machine noise hits all alike. µs/orbit is the
median over repeats (min–max kept). All runs are single-threaded.

Metrics per method and setting, against the reference:
  rel_err_*      |t_end − t_ref| / t_ref over orbits that end (escape or
                 settle) in both; an outcome that differs from the reference
                 counts as an infinite error. ``_short``: orbits with t_ref ≤ 20
                 (less amplified by chaos).
  energy_err_*   conservative: |H(end) − H(0)| / H(0) at the escape point;
                 dissipative: |H(end) − H_ref(end)| / E0 for orbits escaped in
                 both (energy-balance error at the escape point).
  section_err_*  section scene (conservative): max-norm of the state error at
                 the first crossing of ṙ = 0, φ̇ > 0 (where both find one).
"""

from __future__ import annotations

import argparse
import hashlib
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from benchmarks import peers
from benchmarks.config import load_config, machine_note, out_dir
from benchmarks.plots import plot_workprecision
from benchmarks.throughput import measure_throughput, throughput_markdown

SHORT_T = 20.0


@dataclass
class Method:
    """A method at one setting: ``run(ics) -> PeerResult``; ``subset``: number of ICs it runs (None = all)."""

    family: str
    setting: str
    run: Callable
    subset: int | None = None
    section: Callable | None = None  # run(ics) in section mode, or None
    is_engine: bool = False


def scene_ics(energy, gamma, n, seed):
    """scene_ics(E0, γ, n, seed) -> array (n, 4) of disk ICs (the engine's, :func:`hhscatter.scene.ics.region_ics`)."""
    from hhscatter.scene.ics import region_ics  # deferred: pydantic loads on first use
    from hhscatter.scene.scene import Scene  # deferred: pydantic loads on first use

    return region_ics(Scene(energy=energy, gamma=gamma, n=n, seed=seed), 0, n)


def methods_for(kind, cfg) -> list[Method]:
    """methods_for('conservative'|'dissipative', cfg) -> [Method] of the scene."""
    b = cfg["bench"]
    sc = cfg[kind]
    E, g = sc["energy"], sc.get("gamma", 0.0)
    t_max, r_esc = b["t_max"], b["r_esc"]
    out = []
    for tol in sc["engine_tols"]:
        for B in sc["engine_batch"]:
            out.append(
                Method(
                    f"hhscatter engine (batch {B})",
                    f"tol={tol:g}",
                    lambda x, tol=tol, B=B: peers.engine(
                        x, tol, gamma=g, energy=E, r_esc=r_esc, t_max=t_max, batch_size=B
                    ),
                    section=(
                        lambda x, tol=tol, B=B: peers.engine(
                            x, tol, energy=E, r_esc=r_esc, t_max=t_max, batch_size=B, section=True
                        )
                    )
                    if g == 0
                    else None,
                    is_engine=True,
                )
            )
    if g == 0:
        for dt in sc["kl8_dt"]:
            for root in (False, True):
                fam = "KahanLi8 (escape root-found)" if root else "KahanLi8 (escape at step ends)"
                out.append(
                    Method(
                        fam,
                        f"dt={dt:g}",
                        lambda x, dt=dt, root=root: peers.kahanli8(x, dt, r_esc=r_esc, t_max=t_max, rootfind=root),
                        section=lambda x, dt=dt: peers.kahanli8(x, dt, r_esc=r_esc, t_max=t_max, section=True),
                    )
                )
    for tol in sc["dop853_tols"]:
        out.append(
            Method(
                "DOP853 (numba)",
                f"tol={tol:g}",
                lambda x, tol=tol: peers.dop853(x, tol, gamma=g, r_esc=r_esc, t_max=t_max),
                section=(lambda x, tol=tol: peers.dop853(x, tol, r_esc=r_esc, t_max=t_max, section=True))
                if g == 0
                else None,
            )
        )
    for tol in sc["scipy_tols"]:
        out.append(
            Method(
                "SciPy solve_ivp DOP853",
                f"tol={tol:g}",
                lambda x, tol=tol: peers.scipy_dop853(x, tol, gamma=g, r_esc=r_esc, t_max=t_max),
                subset=sc["scipy_n"],
            )
        )
    return out


# -- reference ---------------------------------------------------------------

REF_VERSION = 2  # bump when the reference's definition changes (invalidates cached .npz)


def _key(ics, **kw):
    h = hashlib.sha256(np.ascontiguousarray(ics).tobytes())
    h.update(f"v{REF_VERSION}".encode())
    h.update(repr(sorted(kw.items())).encode())
    return h.hexdigest()[:16]


def cached_reference(ics, cache_dir, *, progress=False, **kw):
    """cached_reference(ics, cache_dir, **kw of reference_orbit) -> dict of arrays (cached as .npz by content hash)."""
    from benchmarks.reference import reference_orbits  # deferred: pydantic loads on first use

    path = cache_dir / f"ref_{_key(ics, **{k: str(v) for k, v in kw.items()})}.npz"
    if path.exists():
        with np.load(path) as z:
            return {k: z[k] for k in z.files}
    t0 = time.perf_counter()
    ref = reference_orbits(ics, **kw)
    ref["seconds"] = np.array(time.perf_counter() - t0)
    np.savez(path, **ref)
    if progress:
        print(f"  reference ({len(ics)} orbits, {kw}) in {float(ref['seconds']):.1f} s", flush=True)
    return ref


def check_reference(ics, ref, cache_dir, **kw):
    """check_reference(ics, ref, cache_dir, **kw) -> dict: long double vs real128 on ``ics`` (first orbits of ref)."""
    import heyoka as hy  # deferred: heyoka loads on first use

    q = cached_reference(ics, cache_dir, fp_type=hy.real128, **kw)
    n = len(ics)
    same = q["outcome"] == ref["outcome"][:n]
    rel = np.abs(ref["t_end"][:n] - q["t_end"]) / q["t_end"]
    return {
        "n": n,
        "outcome_agree": float(same.mean()),
        "max_rel_t_diff": float(rel[same].max()) if same.any() else np.nan,
        "max_state_diff": float(np.abs(ref["state_end"][:n] - q["state_end"]).max()),
    }


# -- metrics -----------------------------------------------------------------


def _q(a, p):
    a = np.asarray(a, dtype=float)
    return float(np.percentile(a, p)) if a.size else np.nan


def accuracy(res, ref, ics, kind):
    """accuracy(PeerResult, ref dict, ics, kind) -> dict of error metrics (module docstring)."""
    n = len(res.t_end)
    ro, rt = ref["outcome"][:n], ref["t_end"][:n]
    same = res.outcome == ro
    ended = same & (ro != 2)
    rel = np.full(n, np.inf)
    rel[ended] = np.abs(res.t_end[ended] - rt[ended]) / rt[ended]
    rel[same & (ro == 2)] = np.nan  # censored in both: no time to compare
    keep = ~np.isnan(rel)
    short = keep & (rt <= SHORT_T)
    x, y, px, py = ref["state_end"][:n].T
    e_ref_end = 0.5 * (px * px + py * py) + 0.5 * (x * x + y * y) + x * x * y - y**3 / 3.0
    x, y, px, py = ics[:n].T
    e0 = 0.5 * (px * px + py * py) + 0.5 * (x * x + y * y) + x * x * y - y**3 / 3.0
    esc = same & (ro == 0)
    if kind == "conservative":
        eerr = np.abs(res.e_end[esc] - e0[esc]) / e0[esc]
    else:
        eerr = np.abs(res.e_end[esc] - e_ref_end[esc]) / e0[esc]
    return {
        "n": n,
        "outcome_mismatch": int((~same).sum()),
        "rel_err_median": _q(rel[keep], 50),
        "rel_err_p99": _q(rel[keep], 99),
        "frac_within_1e-6": float(np.mean(rel[keep] <= 1e-6)) if keep.any() else np.nan,
        "rel_err_p99_short": _q(rel[short], 99),
        "energy_err_median": _q(eerr, 50),
        "energy_err_p99": _q(eerr, 99),
    }


def section_accuracy(res, ref):
    """section_accuracy(PeerResult, ref) -> dict: state error at the first section crossing, and mismatches.

    A mismatch is an orbit where only one of the two finds a crossing, or
    where they find different crossings (times differ by more than 1e-6):
    step-end sign-change detection misses a pair of crossings inside one step.
    The error statistics are over the matched crossings.
    """
    both = (res.outcome == 3) & (ref["outcome"] == 3)
    same_t = both & (np.abs(res.t_end - ref["t_end"]) <= 1e-6 * np.maximum(ref["t_end"], 1.0))
    err = np.abs(res.state_end[same_t] - ref["state_end"][same_t]).max(axis=1) if same_t.any() else np.empty(0)
    mismatch = ((res.outcome == 3) != (ref["outcome"] == 3)) | (both & ~same_t)
    return {"section_err_median": _q(err, 50), "section_err_p99": _q(err, 99), "section_mismatch": int(mismatch.sum())}


# -- the run -----------------------------------------------------------------


def run(cfg, out, *, progress=True):
    """run(cfg, out, progress=True) -> (DataFrame of rows, dict of reference checks). Writes nothing."""
    import pandas as pd  # deferred: pandas loads on first use

    b = cfg["bench"]
    rng = np.random.default_rng(b["seed"])
    rows, checks = [], {}
    for kind in ("conservative", "dissipative"):
        sc = cfg[kind]
        g = sc.get("gamma", 0.0)
        ics = scene_ics(sc["energy"], g, sc["n"], b["seed"])
        kw = {"gamma": g, "r_esc": b["r_esc"], "t_max": b["t_max"]}
        if progress:
            print(f"[{kind}] E0={sc['energy']}, γ={g}, N={len(ics)}: reference …", flush=True)
        ref = cached_reference(ics, out, progress=progress, **kw)
        checks[kind] = check_reference(ics[: cfg["reference"]["real128_n"]], ref, out, **kw)
        sec_ref = None
        if g == 0:
            ns = sc["section_n"]
            sec_ref = cached_reference(ics[:ns], out, progress=progress, section=True, **kw)
            checks["section"] = check_reference(
                ics[: min(ns, cfg["reference"]["real128_n"])], sec_ref, out, section=True, **kw
            )
        ms = methods_for(kind, cfg)
        setup = {}
        for m in ms:  # JIT compilation (numba, heyoka) outside the timings
            m.run(ics[:8])
            if m.is_engine:  # fixed cost per run_chunk call (integrator construction), for the record
                ts = []
                for _ in range(3):
                    t0 = time.perf_counter()
                    m.run(ics[:1])
                    ts.append(time.perf_counter() - t0)
                setup[id(m)] = float(np.median(ts))
        times = {id(m): [] for m in ms}
        results = {}
        for rep in range(b["repeats"]):
            order = rng.permutation(len(ms))
            for j in order:
                m = ms[j]
                x = ics[: m.subset] if m.subset else ics
                t0 = time.perf_counter()
                res = m.run(x)
                times[id(m)].append(1e6 * (time.perf_counter() - t0) / len(x))
                results.setdefault(id(m), res)
            if progress:
                print(f"  repeat {rep + 1}/{b['repeats']} done", flush=True)
        for m in ms:
            x = ics[: m.subset] if m.subset else ics
            us = np.array(times[id(m)])
            row = {
                "scene": kind,
                "family": m.family,
                "setting": m.setting,
                "is_engine": m.is_engine,
                "us_per_orbit": float(np.median(us)),
                "us_min": float(us.min()),
                "us_max": float(us.max()),
                **accuracy(results[id(m)], ref, x, kind),
            }
            if m.is_engine:
                row["setup_ms"] = 1e3 * setup[id(m)]
                row["us_per_orbit_no_setup"] = row["us_per_orbit"] - 1e6 * setup[id(m)] / len(x)
            if m.section is not None and sec_ref is not None:
                row.update(section_accuracy(m.section(ics[: sc["section_n"]]), sec_ref))
            rows.append(row)
    return pd.DataFrame(rows), checks


def speed_ratios(df, metric="rel_err_median"):
    """speed_ratios(df, metric) -> DataFrame: for each engine row and peer family, t_peer / t_engine.

    The peer setting used is the fastest one of its family whose ``metric`` is
    ≤ the engine row's (equal or better accuracy); NaN when no setting of
    the family is that accurate. Ratios > 1: the engine is faster.
    """
    import pandas as pd  # deferred: pandas loads on first use

    out = []
    for scene, d in df.groupby("scene", sort=False):
        eng = d[d.is_engine]
        for _, e in eng.iterrows():
            for fam, p in d[~d.is_engine].groupby("family", sort=False):
                ok = p[p[metric] <= e[metric]]
                if len(ok):
                    best = ok.loc[ok.us_per_orbit.idxmin()]
                    out.append(
                        {
                            "scene": scene,
                            "engine": f"{e.family} {e.setting}",
                            "engine_err": e[metric],
                            "engine_us": e.us_per_orbit,
                            "peer": fam,
                            "peer_setting": best.setting,
                            "peer_err": best[metric],
                            "peer_us": best.us_per_orbit,
                            "ratio": best.us_per_orbit / e.us_per_orbit,
                        }
                    )
                else:
                    out.append(
                        {
                            "scene": scene,
                            "engine": f"{e.family} {e.setting}",
                            "engine_err": e[metric],
                            "engine_us": e.us_per_orbit,
                            "peer": fam,
                            "peer_setting": "none as accurate",
                            "peer_err": p[metric].min(),
                            "peer_us": np.nan,
                            "ratio": np.nan,
                        }
                    )
    return pd.DataFrame(out)


def peer_ratios(df, metric="rel_err_median"):
    """peer_ratios(df, metric) -> DataFrame: for each peer row, t_peer / t(fastest engine row with metric ≤ peer's)."""
    import pandas as pd  # deferred: pandas loads on first use

    out = []
    for scene, d in df.groupby("scene", sort=False):
        eng = d[d.is_engine]
        for _, p in d[~d.is_engine].iterrows():
            ok = eng[eng[metric] <= p[metric]]
            if len(ok):
                e = ok.loc[ok.us_per_orbit.idxmin()]
                out.append(
                    {
                        "scene": scene,
                        "peer": f"{p.family} {p.setting}",
                        "peer_err": p[metric],
                        "peer_us": p.us_per_orbit,
                        "engine": f"{e.family} {e.setting}",
                        "engine_err": e[metric],
                        "engine_us": e.us_per_orbit,
                        "ratio": p.us_per_orbit / e.us_per_orbit,
                    }
                )
    return pd.DataFrame(out)


def _fmt(v, f="{:.2e}"):
    if v is None or (isinstance(v, float) and np.isnan(v)):
        return "—"
    if isinstance(v, float) and np.isinf(v):
        return "inf"
    return f.format(v)


def summary_markdown(df, checks, ratios, pratios, note_start, note_end, seconds, cfg, throughput=None):
    """summary_markdown(...) -> str: the tables of summary.md."""
    L = [
        "# Work–precision benchmark (`make bench`)",
        "",
        f"Scale `{cfg['_scale']}`, config `{cfg['_path']}`. Single-threaded; every method ran the same ICs "
        f"(seed {cfg['bench']['seed']}), {cfg['bench']['repeats']} timing repeats interleaved in shuffled order.",
        f"**Timings were taken on a shared, loaded machine** ({note_start} at start; {note_end} at end): "
        "absolute µs/orbit are noisy, the ratios between methods (same repeats) are the meaningful numbers.",
        f"Total wall time of the benchmark: {seconds:.0f} s.",
        "",
        "Reference: heyoka scalar Taylor in long double at its default tolerance (ε ≈ 1.1e-19), checked against "
        "real128:",
        "",
    ]
    for k, c in checks.items():
        L.append(
            f"- {k}: {c['n']} orbits, outcome agreement {c['outcome_agree']:.3f}, max |Δt|/t = "
            f"{_fmt(c['max_rel_t_diff'])}, max |Δstate| = {_fmt(c['max_state_diff'])}"
        )
    L += [
        "",
        "## Work–precision table",
        "",
        "rel_err: |t_end − t_ref|/t_ref (mismatched outcome = inf); short: orbits with t_ref ≤ 20. "
        "energy_err: conservative |H_end − H_0|/H_0 at the escape point; dissipative |H_end − H_ref,end|/E0 for "
        "escaped orbits. section_err: max-norm state error at the first section crossing (matched crossings); "
        "section mismatch: orbits where the method finds no or another first crossing than the reference "
        "(of `section_n` orbits).",
        "",
        "| scene | method | setting | N | µs/orbit (min–max) | mismatch | rel_err median | p99 | p99 short | "
        "frac ≤1e-6 | energy_err median | p99 | section_err median | p99 | section mismatch |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in df.iterrows():
        L.append(
            f"| {r.scene} | {r.family} | {r.setting} | {r.n} | {r.us_per_orbit:.1f} ({r.us_min:.1f}–{r.us_max:.1f})"
            f" | {r.outcome_mismatch} | {_fmt(r.rel_err_median)} | {_fmt(r.rel_err_p99)} | "
            f"{_fmt(r.rel_err_p99_short)} | {_fmt(r.get('frac_within_1e-6'), '{:.3f}')} | "
            f"{_fmt(r.energy_err_median)} | {_fmt(r.energy_err_p99)} | {_fmt(r.get('section_err_median'))} | "
            f"{_fmt(r.get('section_err_p99'))} | {_fmt(r.get('section_mismatch'), '{:.0f}')} |"
        )
    eng = df[df.is_engine]
    L += [
        "",
        "Engine: fixed cost per `run_chunk` call (integrator construction with heyoka's JIT cache warm; "
        "paid once per chunk of 10,000 orbits in production runs) and µs/orbit with it removed:",
        "",
        "| scene | engine | setup ms/call | µs/orbit measured | µs/orbit without setup |",
        "|---|---|---|---|---|",
    ]
    for _, r in eng.iterrows():
        L.append(
            f"| {r.scene} | {r.family} {r.setting} | {r.setup_ms:.1f} | {r.us_per_orbit:.1f} | "
            f"{r.us_per_orbit_no_setup:.1f} |"
        )
    L += [
        "",
        "## Speed of hhscatter against each peer at equal or better accuracy",
        "",
        "For each engine setting: the fastest setting of each peer whose median relative escape-time error is "
        "≤ the engine's; ratio = t_peer / t_engine (> 1: the engine is faster).",
        "",
        "| scene | engine | engine err | engine µs | peer | peer setting | peer err | peer µs | ratio |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in ratios.iterrows():
        L.append(
            f"| {r.scene} | {r.engine} | {_fmt(r.engine_err)} | {r.engine_us:.1f} | {r.peer} | {r.peer_setting} |"
            f" {_fmt(r.peer_err)} | {_fmt(r.peer_us, '{:.1f}')} | {_fmt(r.ratio, '{:.2f}')} |"
        )
    L += [
        "",
        "For each peer setting: the fastest engine setting at equal or better median error; ratio = t_peer / t_engine.",
        "",
        "| scene | peer | peer err | peer µs | engine | engine err | engine µs | ratio |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for _, r in pratios.iterrows():
        L.append(
            f"| {r.scene} | {r.peer} | {_fmt(r.peer_err)} | {r.peer_us:.1f} | {r.engine} | {_fmt(r.engine_err)} |"
            f" {r.engine_us:.1f} | {r.ratio:.2f} |"
        )
    if throughput is not None:
        L += ["", throughput_markdown(throughput, cfg)]
    return "\n".join(L) + "\n"


def main(argv=None):
    """``python -m benchmarks [--scale full|tiny] [--root DIR] [--no-throughput]``: writes CSV, PNG, summary.md."""

    ap = argparse.ArgumentParser(description="hhscatter work–precision benchmark (make bench)")
    ap.add_argument("--scale", default="full", help="full (default) or tiny")
    ap.add_argument("--root", default=None, help="folder of bench.toml and out/ (default: benchmarks/)")
    ap.add_argument("--no-throughput", action="store_true")
    a = ap.parse_args(argv)
    cfg = load_config("bench", a.scale, a.root)
    out = out_dir("bench", a.scale, a.root)
    t0 = time.perf_counter()
    note0 = machine_note()
    df, checks = run(cfg, out)
    df.to_csv(out / "workprecision.csv", index=False)
    ratios, pratios = speed_ratios(df), peer_ratios(df)
    ratios.to_csv(out / "speed_ratios.csv", index=False)
    pratios.to_csv(out / "peer_ratios.csv", index=False)
    plot_workprecision(out / "workprecision.csv", out / "workprecision.png")
    tp = None
    if not a.no_throughput:
        print("[throughput] …", flush=True)
        tp = measure_throughput(cfg)
        tp.to_csv(out / "throughput.csv", index=False)
    md = summary_markdown(df, checks, ratios, pratios, note0, machine_note(), time.perf_counter() - t0, cfg, tp)
    (out / "summary.md").write_text(md)
    print(md)
    print(f"wrote {out}/workprecision.csv, workprecision.png, speed_ratios.csv, summary.md")


if __name__ == "__main__":
    main()
