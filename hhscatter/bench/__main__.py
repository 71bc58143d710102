"""``python -m hhscatter.bench``: the work–precision benchmark (see :mod:`hhscatter.bench.workprecision`)."""
from hhscatter.bench.workprecision import main

if __name__ == "__main__":
    main()
