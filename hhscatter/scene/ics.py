"""Initial conditions of a region: on the section ṙ = 0, φ̇ > 0 (paper, App. "Initial Conditions"), or not.

Positions are uniform in area in a region; the speed is fixed by the energy,
|p| = √(2(E − V)), and the direction by the scene's ``momentum``:

- 'tangential' (default; the authors' ``goodICs``), on the section:
  ẋ0 = −y0/r0 · √(2(E − V)),   ẏ0 = x0/r0 · √(2(E − V));
- 'random': ẋ0 = cos θ · √(2(E − V)), ẏ0 = sin θ · √(2(E − V)) with θ uniform
  in [0, 2π), a sensitivity row of Fig. 5. These ICs are not on the section;
  the engine records no crossing at t < T_INITIAL, and the first ṙ = 0 root
  with φ̇ > 0 after that is the orbit's first section point.

Determinism: orbits are generated in fixed blocks of ``BLOCK`` orbits; block
b draws from ``numpy.random.Generator(PCG64(SeedSequence(seed, spawn_key=(b,))))``:
first the positions (rejection sampling), then, for 'random', the ``BLOCK``
angles θ. Orbit i is therefore fixed by (seed, i) alone, whatever the chunk
size or the number of workers, and its position is the same in both
conventions.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from hhscatter.errors import ConfigError
from hhscatter.scene.scene import E0_MAX, R_ESC_MAX, Scene

BLOCK = 4096


def _block_rng(seed: int, block: int) -> np.random.Generator:
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(block,))))


def _candidates(rng, region, radius, saddle_radius, m):
    if region == "disk":
        r = radius * np.sqrt(rng.random(m))
        phi = 2 * np.pi * rng.random(m)
        return r * np.cos(phi), r * np.sin(phi)
    # 'well' and 'square': uniform in the square [-r_s, r_s]² (= [-1, 1]² for ω = λ = 1)
    xy = saddle_radius * (2 * rng.random((2, m)) - 1)
    return xy[0], xy[1]


def section_velocities(model, x, y, energy):
    """section_velocities(model, x, y, E) -> (px, py): tangential, φ̇ > 0, |p|² = 2(E − V)."""
    r = np.hypot(x, y)
    v = np.sqrt(2.0 * (energy - model.potential(x, y)))
    return -y / r * v, x / r * v


def chord_lines(model, energy: float, radius: float, n_lines: int, n_per_line: int, rng):
    """chord_lines(model, E, radius, n_lines, n_per_line, rng) -> (states (m, 4), line (m,)): ``n_lines`` lines
    y = const evenly across the disk r < ``radius`` (within 0.8 of it), ``n_per_line`` positions uniform on each
    chord (drawn from ``rng``), tangential momenta at E; the positions where V ≥ E or r = 0 are left out."""
    states, lines = [], []
    for j in range(n_lines):
        c = 0.8 * radius * (2.0 * (j + 0.5) / n_lines - 1.0)
        half = np.sqrt(radius * radius - c * c)
        x = rng.uniform(-half, half, n_per_line)
        y = np.full(n_per_line, c)
        ok = (model.potential(x, y) < energy) & ((x != 0) | (y != 0))
        px, py = section_velocities(model, x[ok], y[ok], energy)
        states.append(np.column_stack([x[ok], y[ok], px, py]))
        lines.append(np.full(int(ok.sum()), j))
    return np.concatenate(states), np.concatenate(lines)


def random_momenta(model, x, y, energy, theta):
    """random_momenta(model, x, y, E, θ) -> (px, py): direction θ (radians), |p|² = 2(E − V(x, y)).

    Example: ``random_momenta(HenonHeiles(), np.array([0.1]), np.array([0.0]), 0.3, np.array([0.0]))`` is
    (√(2(0.3 − V(0.1, 0))), 0).
    """
    v = np.sqrt(2.0 * (energy - model.potential(x, y)))
    return np.cos(theta) * v, np.sin(theta) * v


def sample_block(scene: Scene, block: int) -> np.ndarray:
    """sample_block(scene, block) -> array (BLOCK, 4) of states (x, y, px, py).

    Candidates with V ≥ E, r = 0 or (region 'well') outside the saddle triangle
    are rejected and redrawn from the same block generator. Region 'square' is
    the authors' ``goodICs`` (uniform in [−r_s, r_s]² where V < E): it keeps
    points beyond the saddles, even beyond r_esc (the engine records those as
    escaped at t = 0). With ``scene.momentum == 'random'`` the block's angles are
    drawn after its positions (so the positions are those of 'tangential').
    """
    model = scene.model
    rng = _block_rng(scene.seed, block)
    xs, ys, have = [], [], 0
    while have < BLOCK:
        x, y = _candidates(rng, scene.region, scene.radius, model.saddle_radius, BLOCK)
        ok = (model.potential(x, y) < scene.energy) & ((x != 0) | (y != 0))
        if scene.region == "well":
            ok &= model.inside_well(x, y)
        xs.append(x[ok])
        ys.append(y[ok])
        have += int(ok.sum())
    x = np.concatenate(xs)[:BLOCK]
    y = np.concatenate(ys)[:BLOCK]
    if scene.momentum == "random":
        px, py = random_momenta(model, x, y, scene.energy, 2.0 * np.pi * rng.random(BLOCK))
    else:
        px, py = section_velocities(model, x, y, scene.energy)
    return np.column_stack([x, y, px, py])


def region_ics(scene: Scene, start: int, stop: int) -> np.ndarray:
    """region_ics(scene, start, stop) -> array (stop − start, 4) for orbits start..stop−1."""
    blocks = range(start // BLOCK, (stop - 1) // BLOCK + 1)
    arr = np.concatenate([sample_block(scene, b) for b in blocks])
    off = start - blocks[0] * BLOCK
    return arr[off : off + (stop - start)]


def read_ics_table(path) -> tuple[np.ndarray, np.ndarray]:
    """read_ics_table(path) -> (states (n, 4), traj_id (n,) int64) from Parquet or CSV.

    Required columns: x, y, px, py (float); optional traj_id (unique int).
    Missing columns, non-finite values or duplicate ids raise ConfigError.
    Read with pyarrow (Parquet: only these columns), not pandas, whose import
    alone cost a third of a second of every ``simulate --ics``.
    Example: ``states, ids = read_ics_table("ics.parquet")``.
    """
    path = Path(path)
    if not path.exists():
        raise ConfigError(f"ics: file not found: {path}")
    try:
        if path.suffix.lower() in (".parquet", ".pq"):
            import pyarrow.parquet as pq  # deferred: pyarrow loads on first use

            f = pq.ParquetFile(path)  # (pq.read_table goes through pyarrow.dataset, which imports pandas)
            names = set(f.schema_arrow.names)
            table = f.read(columns=[c for c in ("x", "y", "px", "py", "traj_id") if c in names])
        else:
            import pyarrow.csv as pcsv  # deferred: pyarrow loads on first use

            table = pcsv.read_csv(path)
    except Exception as exc:  # noqa: BLE001 - any reader failure is the user's file
        raise ConfigError(f"ics: cannot read {path}: {exc}") from None
    names = list(table.column_names)
    twice = sorted({c for c in names if names.count(c) > 1 and c in ("x", "y", "px", "py", "traj_id")})
    if twice:
        raise ConfigError(
            f"ics: table {path} has column(s) {twice} more than once: which one holds the initial "
            "states is ambiguous; keep one of each"
        )
    missing = [c for c in ("x", "y", "px", "py") if c not in table.column_names]
    if missing:
        raise ConfigError(f"ics: table {path} lacks column(s) {missing}; required: x, y, px, py")
    if table.num_rows == 0:
        raise ConfigError(f"ics: table {path} has no rows")
    try:
        states = np.column_stack([_column(table, c, float) for c in ("x", "y", "px", "py")])
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"ics: columns x, y, px, py must be numeric: {exc}") from None
    bad = ~np.isfinite(states).all(axis=1)
    if bad.any():
        raise ConfigError(f"ics: {int(bad.sum())} row(s) have non-finite values (first at row {int(np.argmax(bad))})")
    if "traj_id" in table.column_names:
        try:
            ids = _column(table, "traj_id", int)
        except (TypeError, ValueError):
            raise ConfigError("ics: traj_id must be integers") from None
        if len(np.unique(ids)) != len(ids):
            raise ConfigError("ics: traj_id values must be unique")
    else:
        ids = np.arange(table.num_rows, dtype=np.int64)
    return states, ids


def _column(table, name, kind) -> np.ndarray:
    """Column ``name`` of a pyarrow table as float64 (``kind`` float: integers converted, nulls NaN) or int64
    (``kind`` int: integers without nulls), else TypeError. Read from the Arrow buffer: pyarrow's own
    ``to_numpy`` imports pandas."""
    import pyarrow as pa  # deferred: pyarrow loads on first use

    col = table.column(name)
    t = col.type
    if kind is float:
        if not (pa.types.is_integer(t) or pa.types.is_floating(t) or pa.types.is_null(t)):
            raise TypeError(f"column {name} of type {t}")
        arr = col.cast(pa.float64(), safe=False).combine_chunks()
        if arr.null_count == len(arr):
            return np.full(len(arr), math.nan)
        out = np.frombuffer(arr.buffers()[1], dtype=np.float64, count=len(arr), offset=arr.offset * 8).copy()
        if arr.null_count:  # (nulls as NaN: refused as non-finite by the caller)
            valid = np.unpackbits(np.frombuffer(arr.buffers()[0], np.uint8), bitorder="little")
            out[valid[arr.offset : arr.offset + len(arr)] == 0] = math.nan
        return out
    if not pa.types.is_integer(t) or col.null_count:
        raise TypeError(f"column {name} of type {t} with {col.null_count} null(s)")
    arr = col.cast(pa.int64()).combine_chunks()
    return np.frombuffer(arr.buffers()[1], dtype=np.int64, count=len(arr), offset=arr.offset * 8).copy()


def check_ics(scene: Scene, states: np.ndarray) -> None:
    """check_ics(scene, states) -> None; ConfigError before any work if a table row cannot be run honestly.

    Bounds (the reasons of :mod:`hhscatter.scene.scene`): every row's position within R_ESC_MAX r_s of the
    origin (r_s the system's saddle radius) and energy H = |p|²/2 + V ≤ E0_MAX·E_c (energy conservation,
    overflow). Rows below E_c inside Ω (r < r_esc) in a dissipative scene are refused: drag only lowers the energy, so such an orbit can
    neither escape nor cross E = E_c from above: it has "settled" before it starts, and none of the
    outcomes (whose settling time is the root of E = E_c) describes it. Conservative rows below E_c are
    fine: they stay inside Ω and are censored at t_max, which is the correct outcome.
    Example: ``check_ics(scene, np.array([[0.1, 0.0, 0.0, 0.8]]))``.
    """
    m = scene.model
    x, y, px, py = (states[:, k] for k in range(4))
    r = np.hypot(x, y)
    far = r > R_ESC_MAX * m.saddle_radius
    if far.any():
        i = int(np.argmax(far))
        raise ConfigError(
            f"ics: {int(far.sum())} row(s) start beyond r = {R_ESC_MAX:g} r_s = {R_ESC_MAX * m.saddle_radius:g} "
            f"(first: row {i}, r = {r[i]:.3g}); energy conservation fails that far out"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        e = m.energy(x, y, px, py)
    high = ~(e <= E0_MAX * m.critical_energy)
    if high.any():
        i = int(np.argmax(high))
        raise ConfigError(
            f"ics: {int(high.sum())} row(s) have an energy above {E0_MAX:g} E_c = "
            f"{E0_MAX * m.critical_energy:.6g} (first: row {i}, E = {e[i]:.3g}; momenta too large: "
            "every orbit leaves at once, p² overflows near 1e308)"
        )
    if scene.gamma > 0:
        low = (e <= m.critical_energy) & (r < scene.r_esc)
        if low.any():
            i = int(np.argmax(low))
            raise ConfigError(
                f"ics: {int(low.sum())} row(s) start below E_c = {m.critical_energy:.10g} inside r_esc with drag "
                f"γ = {scene.gamma:g} (first: row {i}, E = {e[i]:.6g}): such an orbit can never escape and never "
                "crosses E_c from above, so it has no outcome; drop these rows (they are trapped from t = 0)"
            )


def section_grid(model, energy: float, extent, shape):
    """section_grid(model, E, extent, shape) -> (x (nx,), y (ny,), allowed (ny, nx), states (m, 4), cell (m,)).

    Initial conditions on a regular grid of the section ṙ = 0, φ̇ > 0 at
    energy E (paper, App. "Initial Conditions"): cell centres
    x_i = x0 + (i + ½)Δx, y_j = y0 + (j + ½)Δy over ``extent`` = (x0, x1, y0,
    y1) with ``shape`` = (ny, nx) cells; the allowed cells (V < E, r > 0) get
    the tangential velocity of :func:`section_velocities`. ``cell`` is each
    state's flat index into the (ny, nx) grid (row-major), so outcomes map
    back to a basin image as ``image.flat[cell] = outcome``.
    """
    x0, x1, y0, y1 = (float(v) for v in extent)
    ny, nx = (int(v) for v in shape)
    if not (x1 > x0 and y1 > y0):
        raise ValueError(f"extent must be (x0, x1, y0, y1) with x1 > x0 and y1 > y0, got {extent!r}")
    if nx < 1 or ny < 1:
        raise ValueError(f"shape must be (ny, nx) with positive sizes, got {shape!r}")
    x = x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx
    y = y0 + (np.arange(ny) + 0.5) * (y1 - y0) / ny
    X, Y = np.meshgrid(x, y)
    allowed = (model.potential(X, Y) < energy) & ((X != 0) | (Y != 0))
    cell = np.flatnonzero(allowed)
    px, py = section_velocities(model, X.flat[cell], Y.flat[cell], energy)
    return x, y, allowed, np.column_stack([X.flat[cell], Y.flat[cell], px, py]), cell


def perturbed_on_section(model, states, energy: float, dx: float = 0.0, dy: float = 0.0):
    """perturbed_on_section(model, states, E, dx, dy) -> (states (m, 4), ok (m,)): positions moved by (dx, dy),
    still on the section at energy E (tangential velocity recomputed).

    The uncertainty algorithm's perturbed copies of a set of initial
    conditions: each position (x, y) → (x + dx, y + dy) and a new tangential
    velocity at E. ``ok`` is False where the moved point is not allowed (V ≥ E
    or r = 0); those rows are NaN.
    """
    s = np.asarray(states, dtype=float)
    x, y = s[:, 0] + dx, s[:, 1] + dy
    ok = (model.potential(x, y) < energy) & ((x != 0) | (y != 0))
    out = np.full((len(s), 4), np.nan)
    px, py = section_velocities(model, x[ok], y[ok], energy)
    out[ok] = np.column_stack([x[ok], y[ok], px, py])
    return out, ok
