"""hhscatter: exact-event ensemble simulations of (dissipative) chaotic scattering
in the Hénon–Heiles potential, on heyoka's batch Taylor integrator.

Public entry points (imported lazily, so ``import hhscatter`` is cheap and has
no side effects):

- :class:`Scene`, :class:`SectionWindow`, :func:`load_scene` — what to compute
- :func:`simulate` — run a scene, write Parquet tables
- :func:`read_lifetimes`, :func:`read_sections`, :func:`read_snapshots` — read them
- :class:`HenonHeiles` — the model's closed forms (E_c, saddles, channels)
"""

__version__ = "0.1.0"

_EXPORTS = {
    "Scene": "scene",
    "SectionWindow": "scene",
    "SceneError": "scene",
    "load_scene": "scene",
    "simulate": "runner",
    "read_lifetimes": "tables",
    "read_sections": "tables",
    "read_snapshots": "tables",
    "HenonHeiles": "model",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module 'hhscatter' has no attribute {name!r}")
