"""``python -m benchmarks.noise``: the cost of noise, as ratios measured in one run.

Time per unit of orbit time (µs of wall time per orbit per time unit, one process, warm integrators) of:

* ``conservative``: Hénon–Heiles at E0 = 0.3 without noise (the stream scheduler);
* ``noise``: the same orbits with a noise strength σ = 0.01 and no drag (the noise scheduler, default kick);
* ``heat bath``: γ = 1, T = ΔE/6 from the well (long orbits: ≈ 2400 time units each), with the noise
  scheduler's default batch and (``heat bath, B lanes``, to t = 300) with B = 8 and 16 lanes: the Python per
  kick shared by the batch;
* ``numpy OBABO``: the independent vectorised integrator (:mod:`hhscatter.integrate.noise_reference`) on the
  heat-bath case, at the step where its weak error on ⟨V⟩ is as small as the engine's.

Equal weak error: the engine's splitting (exact Hamiltonian flow, exact Ornstein–Uhlenbeck kicks) leaves the
Boltzmann density invariant exactly, so its stationary ⟨V⟩ carries no splitting error at any kick interval;
the numpy OBABO's carries O(h²): h²ω²/4 at leading order in a harmonic well (Leimkuhler & Matthews, Appl.
Math. Res. Express 2013), so it is timed at h = 2√BIAS/ω, its bias then ``BIAS`` (0.5 %, about the engine's
statistical resolution of ⟨K⟩ and ⟨V⟩ in the tests at 3000 orbits). The run checks the leading order where
it is measurable: ⟨V⟩'s relative bias at h = 0.2 in the deep well (ΔE/T = 10) against the Boltzmann
quadrature (expected ≈ +1 %). Results: a Markdown table and JSON in benchmarks/out/noise/.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from hhscatter.integrate.chunk import run_chunk
from hhscatter.integrate.noise import NOISE_BATCH
from hhscatter.integrate.noise_reference import obabo_escape_times
from hhscatter.model import HenonHeiles
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Noise, Scene

OUT = Path(__file__).resolve().parent / "out" / "noise"
BIAS = 0.005  # the weak error (relative bias of ⟨V⟩) at which the numpy reference is timed
DELTA_E = 1.0 / 6.0


def _engine(scene, n, batch_size=None):
    """µs per unit of orbit time of the engine on ``n`` orbits of ``scene`` (integrator compiled beforehand)."""
    ics = region_ics(scene, 0, n)
    run_chunk(scene, ics[:8], np.arange(8), batch_size=batch_size)  # compile
    t = time.perf_counter()
    lt = run_chunk(scene, ics, np.arange(n), batch_size=batch_size).lifetimes
    dt = time.perf_counter() - t
    return 1e6 * dt / float(lt["t_end"].sum())


def _boltzmann_mean_v(model, T, r_max=1.0, nr=3000, nth=720):
    r = np.linspace(0.0, r_max, nr)
    th = np.linspace(0.0, 2 * np.pi, nth, endpoint=False)
    R, TH = np.meshgrid(r, th, indexing="ij")
    V = model.potential(R * np.cos(TH), R * np.sin(TH))
    w = np.exp(-V / T) * R
    return float((V * w).sum() / w.sum())


def _obabo_mean_v(model, T, h, n=2000, t_relax=20.0, t_run=200.0, seed=1):
    """Time- and ensemble-averaged ⟨V⟩ of the numpy OBABO in the deep well (positions sampled every step; the
    rare orbit that leaves r < 1.5 (probability ≈ 1e-4 per orbit) is put back at rest at the origin, uncounted)."""
    from hhscatter.integrate.noise import ou_coefficients

    rng = np.random.default_rng(seed)
    x = np.zeros(n)
    y = np.zeros(n)
    px = np.zeros(n)
    py = np.zeros(n)
    c, s = ou_coefficients(1.0, math.sqrt(2 * T), 0.5 * h)
    acc, cnt = 0.0, 0
    for k in range(int((t_relax + t_run) / h)):
        xi = rng.standard_normal((4, n))
        px, py = c * px + s * xi[0], c * py + s * xi[1]
        fx, fy = model.force(x, y)
        px, py = px + 0.5 * h * fx, py + 0.5 * h * fy
        x, y = x + h * px, y + h * py
        fx, fy = model.force(x, y)
        px, py = px + 0.5 * h * fx, py + 0.5 * h * fy
        px, py = c * px + s * xi[2], c * py + s * xi[3]
        out = x * x + y * y > 2.25
        if out.any():
            x[out] = y[out] = px[out] = py[out] = 0.0
        if k * h >= t_relax:
            acc += float(model.potential(x, y)[~out].sum())
            cnt += int((~out).sum())
    return acc / cnt


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=2000, help="orbits of the engine cases")
    a = ap.parse_args(argv)
    model = HenonHeiles()
    rows = {}
    cons = Scene(energy=0.3, n=a.n, seed=1, t_max=200.0)
    rows["conservative"] = _engine(cons, a.n)
    rows["noise"] = _engine(cons.replace(noise=Noise(sigma=0.01)), a.n)
    T6 = DELTA_E / 6
    bath = Scene(energy=0.05, n=a.n // 10, gamma=1.0, seed=1, t_max=2000.0, noise=Noise(temperature=T6))
    rows["heat bath"] = _engine(bath, a.n // 10)
    short = bath.replace(t_max=300.0)
    for b in (8, 16, NOISE_BATCH):
        rows[f"heat bath, {b} lanes"] = _engine(short, 128, batch_size=b)
    # the numpy reference's weak error: its leading order checked at h = 0.2, its cost at bias BIAS
    T10 = DELTA_E / 10
    bias = {0.2: _obabo_mean_v(model, T10, 0.2) / _boltzmann_mean_v(model, T10) - 1}
    h_eq = 2 * math.sqrt(BIAS) / model.frequency
    ics = region_ics(bath, 0, a.n // 10)
    t = time.perf_counter()
    t_end, _ = obabo_escape_times(
        model, ics, gamma=1.0, sigma=math.sqrt(2 * T6), h=h_eq, t_max=bath.t_max, r_esc=bath.r_esc, seed=1
    )
    rows["numpy OBABO"] = 1e6 * (time.perf_counter() - t) / float(t_end.sum())
    out = {
        "us_per_unit_orbit_time": rows,
        "ratios": {
            "noise / conservative": rows["noise"] / rows["conservative"],
            "heat bath / conservative": rows["heat bath"] / rows["conservative"],
            "heat bath / numpy OBABO at equal weak error": rows["heat bath"] / rows["numpy OBABO"],
            f"heat bath, 8 lanes / {NOISE_BATCH} lanes": rows["heat bath, 8 lanes"]
            / rows[f"heat bath, {NOISE_BATCH} lanes"],
        },
        "numpy_obabo_bias_of_mean_V": {str(h): b for h, b in bias.items()},
        "numpy_obabo_step_at_equal_weak_error": h_eq,
        "engine_kick": bath.kick_interval,
        "n": a.n,
    }
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "noise.json").write_text(json.dumps(out, indent=1))
    lines = ["| case | µs per unit orbit time |", "|---|---|"]
    lines += [f"| {k} | {v:.3g} |" for k, v in rows.items()]
    lines += ["", "| ratio | value |", "|---|---|"] + [f"| {k} | {v:.3g} |" for k, v in out["ratios"].items()]
    lines += [
        "",
        f"numpy OBABO: relative bias of ⟨V⟩ at ΔE/T = 10, h = 0.2: {bias[0.2]:+.2%} (leading order h²/4: +1%);",
    ]
    lines += [f"timed at h = {h_eq:.3g} (bias {BIAS:.1%}); the engine at kick {bath.kick_interval:g} (no bias on ⟨V⟩)"]
    (OUT / "summary.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
