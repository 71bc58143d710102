"""Statistics shared by the analyses: weighted least squares, binomial intervals, verdict wording, the libraries'
warnings counted.

Every public name of its modules is importable from here (loaded on first use).
"""

from hhscatter._exports import lazy_exports

_EXPORTS, __getattr__, __dir__ = lazy_exports(__name__)
__all__ = sorted(_EXPORTS)
