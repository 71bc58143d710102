"""Memory: simulation O(chunk) whatever N; P(t) inputs read with column projection (~9 bytes/orbit)."""

import os
import subprocess
import sys
import threading
import time
import tracemalloc
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

import numpy as np
import pytest

from hhscatter.run.runner import _drain, simulate
from hhscatter.scene.scene import Scene


def test_client_keeps_a_bounded_window_of_tasks():
    """The client never holds more than `window` submitted tasks, whatever the number of chunks."""
    lock, live, peak = threading.Lock(), [0], [0]

    def work(i):
        time.sleep(0.001)
        return i * i

    with ThreadPoolExecutor(4) as ex:

        def submit(task):
            with lock:
                live[0] += 1
                peak[0] = max(peak[0], live[0])
            return ex.submit(work, task)

        got = {}

        def on_done(task, result):
            with lock:
                live[0] -= 1
            got[task] = result

        _drain(
            submit, lambda fs: wait(fs, return_when=FIRST_COMPLETED).done, range(1, 301), 6, on_done, lambda fs: None
        )
    assert got == {i: i * i for i in range(1, 301)} and peak[0] <= 6


def test_a_failing_task_stops_submission_and_cancels_the_rest():
    submitted, cancelled = [], []

    def work(i):
        if i == 3:
            raise OSError(28, "No space left on device")
        return i

    with ThreadPoolExecutor(1) as ex, pytest.raises(OSError, match="No space"):
        _drain(
            lambda t: submitted.append(t) or ex.submit(work, t),
            lambda fs: wait(fs, return_when=FIRST_COMPLETED).done,
            range(100),
            4,
            lambda t, r: None,
            lambda fs: cancelled.extend(fs),
        )
    assert len(submitted) < 10 and cancelled


def _traced_peak(scene, tmp):
    tracemalloc.start()
    try:
        simulate(scene, tmp, workers=1, progress=False)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_simulation_memory_does_not_grow_with_n(tmp_path):
    """Peak Python/numpy memory (tracemalloc) for 15 and 40 chunks of the same size: equal within 0.2 MB.

    Both runs cross an IC block boundary (4096 orbits; a chunk there draws two blocks, +0.26 MB).
    A run that kept its rows would need ≥ 100 bytes per orbit more, i.e. +0.75 MB here (the
    lifetimes rows alone are 83 bytes per orbit), far above the tolerance. (Before the engine
    released each chunk's integrator, this measured +250 bytes per orbit.)
    """
    sc = Scene(energy=0.35, n=4500, seed=1, chunk_size=300)
    simulate(sc.replace(n=300), tmp_path / "warm", workers=1, progress=False)  # JIT and imports outside
    small = _traced_peak(sc, tmp_path / "a")
    big = _traced_peak(sc.replace(n=12000), tmp_path / "b")
    print(f"traced peak: N=4500 {small / 1e6:.2f} MB, N=12000 {big / 1e6:.2f} MB")
    assert big - small < 0.2e6


_READ = """
import sys
import numpy as np, pandas, pyarrow.dataset, pyarrow.parquet
from hhscatter.api import stream_survival
from hhscatter.data.read import read_lifetimes, survival_arrays
from hhscatter.analysis.survival.fits import survival_curve
def status(key):
    for line in open('/proc/self/status'):
        if line.startswith(key):
            return int(line.split()[1])
grid = np.linspace(0, 50, 51)
read = {'lean': survival_arrays, 'full': read_lifetimes, 'grid': lambda d: stream_survival(d, grid)}[sys.argv[2]]
read(sys.argv[3])  # warm up the reading path (libraries, thread pools) on a one-part dataset
open('/proc/self/clear_refs', 'w').write('5')  # reset the peak RSS (VmHWM) to the current RSS
before = status('VmRSS:')
if sys.argv[2] == 'grid':
    c = stream_survival(sys.argv[1], grid)
    print(status('VmHWM:') - before, -1, -1, c.P[10])
    sys.exit()
if sys.argv[2] == 'lean':
    t, obs = survival_arrays(sys.argv[1])
else:
    df = read_lifetimes(sys.argv[1])
    t, obs = df['t_end'].to_numpy(), (df['outcome'] != 'censored').to_numpy()
extra = status('VmHWM:') - before
c = survival_curve(t, obs, t_grid=grid)
print(extra, int(t.size), int((~obs).sum()), c.P[10])
"""


@pytest.mark.skipif(not os.access("/proc/self/clear_refs", os.W_OK), reason="needs Linux /proc/self/clear_refs")
def test_survival_inputs_are_read_with_column_projection(tmp_path):
    """P(t) from survival_arrays / survival_on_grid equals P(t) from the full table, at a fraction of the memory."""
    from hhscatter.data.schema import part_name, to_arrow
    from hhscatter.data.write import write_part

    rng = np.random.default_rng(0)
    n_part, parts = 100_000, 4
    t_max = 60.0
    for k in range(parts):
        if k == 1:  # a one-part copy for the warm-up
            (tmp_path / "warm" / "lifetimes").mkdir(parents=True)
            import shutil

            shutil.copy(tmp_path / "lifetimes" / part_name(0), tmp_path / "warm" / "lifetimes")
            (tmp_path / "warm" / "scene.json").write_text("{}")  # a run written before manifests: read by listing
        t = rng.exponential(1 / 0.15, n_part)
        outcome = np.where(t > t_max, 2, 0).astype(np.int8)
        t = np.minimum(t, t_max)
        cols = {c: rng.random(n_part) for c in ("x0", "y0", "px0", "py0", "e0", "gamma", "e_end")}
        cols.update(
            traj_id=np.arange(k * n_part, (k + 1) * n_part),
            outcome=outcome,
            t_end=t,
            exit_channel=np.where(outcome == 0, k % 3, -1),
        )
        write_part(tmp_path / "lifetimes" / part_name(k), to_arrow("lifetimes", cols), {"rows": n_part})
    (tmp_path / "scene.json").write_text("{}")  # a run written before manifests: read by listing its parts
    res = {}
    for mode in ("lean", "full", "grid"):
        out = subprocess.run(
            [sys.executable, "-c", _READ, str(tmp_path), mode, str(tmp_path / "warm")],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()
        res[mode] = (int(out[0]) / 1024, int(out[1]), int(out[2]), float(out[3]))
    n = n_part * parts
    lean, full, grid = res["lean"], res["full"], res["grid"]
    print(
        f"extra peak RSS for {n} orbits: survival_arrays {lean[0]:.0f} MB, read_lifetimes {full[0]:.0f} MB, "
        f"survival_on_grid {grid[0]:.0f} MB"
    )
    # streaming P(t) on a grid: the Kaplan–Meier value, in memory independent of N (one part at a time;
    # `make bench-memory` shows it flat from 1e5 to 1e7 orbits)
    assert grid[3] == pytest.approx(full[3], abs=1e-12) and grid[0] < 40  # 12-18 MB: one part + reader pools
    assert lean[1:] == full[1:] and lean[1] == n
    # P(10) of an exponential with κ = 0.15 (censoring at 60 does not touch t = 10)
    assert lean[3] == pytest.approx(np.exp(-1.5), abs=5 * np.sqrt(np.exp(-1.5) / n))
    # reading keeps 9 bytes per orbit (+ transient copies and reader buffers, ~50 measured); the
    # full read holds 11 columns (≥ 88 bytes per orbit, ~270 measured with pandas' objects)
    assert lean[0] < 0.3 * full[0]
    assert lean[0] < 80 * n / 2**20


def test_survival_on_grid_equals_kaplan_meier(tmp_path):
    """Streamed counts vs survival_curve (Kaplan–Meier) on the same lifetimes, with ties and censoring at t_max."""
    from hhscatter.analysis.survival.fits import survival_curve
    from hhscatter.api import stream_survival
    from hhscatter.data.schema import part_name, to_arrow
    from hhscatter.data.write import write_part

    rng = np.random.default_rng(3)
    t_all, obs_all = [], []
    for k in range(3):
        n = 1000
        t = rng.exponential(10.0, n)
        outcome = np.where(t > 50, 2, k % 2).astype(np.int8)  # escaped / settled both leave Ω
        t = np.minimum(t, 50.0)
        t[:50] = np.round(t[:50])  # ties with the grid times
        cols = {c: rng.random(n) for c in ("x0", "y0", "px0", "py0", "e0", "gamma", "e_end")}
        cols.update(
            traj_id=np.arange(k * n, (k + 1) * n), outcome=outcome, t_end=t, exit_channel=np.where(outcome == 0, 0, -1)
        )
        write_part(tmp_path / "lifetimes" / part_name(k), to_arrow("lifetimes", cols), {"rows": n})
        t_all.append(t)
        obs_all.append(outcome != 2)
    g = np.array([0.0, 0.5, 1.0, 2.0, 3.0, 10.0, 20.0, 49.5, 50.0])
    (tmp_path / "scene.json").write_text("{}")  # a run written before manifests: read by listing its parts
    got = stream_survival(tmp_path, g)
    ref = survival_curve(np.concatenate(t_all), np.concatenate(obs_all), t_grid=g)
    assert np.allclose(got.P, ref.P, rtol=0, atol=1e-15) and np.allclose(got.P_err, ref.P_err, rtol=1e-12)
    with pytest.raises(ValueError, match="censored at t = 50 < max"):
        stream_survival(tmp_path, [1.0, 60.0])
