"""Benchmarks and stress tests of hhscatter, outside the installed package: ``make bench``, ``make bench-engine``,
``make bench-memory`` and ``make stress``, run from the repository root (``python -m benchmarks…``).

Modules: :mod:`.peers` (KahanLi8 and DOP853 compiled with numba, SciPy's
DOP853, the engine behind one interface), :mod:`.reference` (heyoka long
double / real128 reference orbits), :mod:`.workprecision` (work–precision
tables, plot, summary), :mod:`.throughput` (engine µs/orbit, 1 and all
workers), :mod:`.stress` (numerical stability cases), :mod:`.engine` (engine targets as ratios),
:mod:`.memory` (peak memory against N). Configurations ``<name>.toml`` here, results under ``out/<name>/<scale>/``.
numba is needed only by the peers (extra ``bench``).
"""
