"""The engine benchmark's contenders (benchmarks/engine.py) compute what they are compared on: the
minimal driver's escape and censoring times equal the engine's (an independent driver: its own integrator,
bound-censored, single-length lane clock; with a short t_max its stale bounds once censored ~1 orbit in 500
early), and the driver reads an IC table to the same orbits as it samples. Timings are not
tested (speed claims live in `make bench-engine`)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from benchmarks.engine import design_choices, yardstick
from hhscatter.integrate.engine import CENSORED, run_chunk
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene


def test_yardstick_escape_times_equal_the_engines():
    sc = Scene(energy=0.27, n=600, seed=1, r_esc=1.03, t_max=300.0)
    ics = region_ics(sc, 0, sc.n)
    ty = yardstick(ics, r_esc=1.03, t_max=300.0)
    res = run_chunk(sc, ics, np.arange(sc.n))
    te, out = res.lifetimes["t_end"], res.lifetimes["outcome"]
    assert (out != CENSORED).sum() > 500
    # the same steps: equal up to the driver's single-length lane clock (hi − start, not TwoSum)
    close = np.abs(te - ty) <= 1e-9 * np.maximum(1.0, ty)
    assert close.all(), (int((~close).sum()), te[~close][:5], ty[~close][:5])


def test_driver_reads_an_ic_table_to_the_orbits_it_samples(tmp_path):
    n = 300
    ics = region_ics(Scene(energy=0.27, n=n, seed=1), 0, n)
    pq.write_table(pa.table({c: ics[:, i] for i, c in enumerate(("x", "y", "px", "py"))}), tmp_path / "ics.parquet")
    for args in ([], [str(tmp_path / "ics.parquet")]):
        out = tmp_path / f"t{len(args)}.parquet"
        subprocess.run(
            [sys.executable, "-m", "benchmarks.engine", "--driver", str(n), "1", str(out), *args],
            check=True,
            capture_output=True,
        )
    a, b = (pq.read_table(tmp_path / f"t{k}.parquet").column("t_end").to_numpy() for k in (0, 1))
    assert len(a) == n and np.array_equal(a, b)


def test_design_choices_run_every_way_of_recording():
    out = design_choices(batch_size=4, epochs=4, epoch=2.0)
    assert set(out) == {"until", "grid2", "grid17", "step callback", "c_output", "c_output long"}
    assert all(np.isfinite(v) and v > 0 for v in out.values())


@pytest.mark.slow
def test_saddle_rows_report_each_estimator_with_its_precision():
    """The saddle rows (``--only saddle``): one row per estimator, a CPU time > 0 and the precision it reached in
    its note (the value ± error of κ, λ̄, D₁ and d₀ printed there)."""
    from benchmarks.engine import _saddle_rows

    rows = []
    _saddle_rows(lambda target, what, value, goal, note="": rows.append((target, what, value, note)), 20_000)
    assert [w.split(":")[0] for _, w, _, _ in rows] == [
        "saddle points",
        "λ̄ with its convergence",
        "d₁ (section)",
        "d₀ = 1 − α (lines)",
    ]
    assert all(t == "saddle" and v > 0 and "±" in n for t, _, v, n in rows)


def test_update_replaces_the_measured_targets_rows_and_keeps_the_others(tmp_path):
    """``--only ... --update``: the rows of the targets measured replace theirs in the engine.csv already there,
    the other rows stay as they were (targets new to the file first), and the summary says which run each came
    from."""
    import pandas as pd

    from benchmarks.engine import _write_outputs

    def rows(*items):
        return [{"target": t, "measure": m, "value": v, "goal": "", "note": ""} for t, m, v in items]

    _write_outputs(rows(("bare", "a", 1.0), ("recording", "b", 2.0), ("recording", "c", 3.0), ("whole", "d", 4.0)),
                   tmp_path, 100_000, 3)  # fmt: skip
    _write_outputs(rows(("alternated", "e", 5.0), ("recording", "b", 6.0)), tmp_path, 20_000, 5, update=True)
    df = pd.read_csv(tmp_path / "engine.csv", keep_default_na=False)
    assert list(zip(df["target"], df["measure"], df["value"])) == [
        ("alternated", "e", 5.0),
        ("bare", "a", 1.0),
        ("recording", "b", 6.0),
        ("whole", "d", 4.0),
    ]
    head = (tmp_path / "engine_summary.md").read_text().splitlines()[0]
    assert "alternated, recording" in head and "N = 20000" in head and "earlier run" in head
