"""``python -m hhscatter.bench``: the work–precision benchmark (see :mod:`hhscatter.bench.workprecision`)."""
from .workprecision import main

if __name__ == "__main__":
    main()
