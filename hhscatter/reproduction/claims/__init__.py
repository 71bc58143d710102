"""The paper's claims tested on a system, and the evidence behind their readings (regular orbits, long-time escape).

Every public name of its modules is importable from here (loaded on first use).
"""

from hhscatter._exports import lazy_exports

_EXPORTS, __getattr__, __dir__ = lazy_exports(__name__)
__all__ = sorted(_EXPORTS)
