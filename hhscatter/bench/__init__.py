"""Benchmarks and stress tests: ``make bench`` and ``make stress``.

Modules: :mod:`.peers` (KahanLi8 and DOP853 compiled with numba, SciPy's
DOP853, the engine behind one interface), :mod:`.reference` (heyoka long
double / real128 reference orbits), :mod:`.workprecision` (work–precision
tables, plot, summary), :mod:`.throughput` (engine µs/orbit, 1 and all
workers), :mod:`.stress` (numerical stability cases). numba is needed only by
the peers (extra ``bench``).
"""
