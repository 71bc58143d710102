"""The installed distribution's version (``pyproject.toml`` is its only source), recorded in every table's metadata."""

from importlib.metadata import PackageNotFoundError, version

__all__ = ["__version__"]

try:
    __version__ = version("hhscatter")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
del version, PackageNotFoundError
