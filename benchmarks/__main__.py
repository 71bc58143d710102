"""``python -m benchmarks``: the work–precision benchmark (see :mod:`benchmarks.workprecision`)."""

from benchmarks.workprecision import main

if __name__ == "__main__":
    main()
