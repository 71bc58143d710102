"""hhscatter: exact-event ensemble simulations of (dissipative) chaotic scattering
in the Hénon–Heiles potential and any open two-degree-of-freedom system declared as data, on heyoka's
batch Taylor integrator.

Public entry points (imported lazily, so ``import hhscatter`` is cheap and has
no side effects; ``dir(hhscatter)`` lists them):

- :class:`Scene`, :class:`SectionWindow`, :class:`Noise`, :func:`load_scene`, :class:`Grid`,
  :func:`load_run` — what to compute (one scene, or a grid over E0 and γ; what it records, random forces)
- :func:`simulate` — run a scene or a grid, write Parquet tables
- :func:`read_lifetimes`, :func:`read_sections`, :func:`read_snapshots` — read them
- :func:`survival`, :func:`escape_rates` — P(t) and κ per grid point of a
  lifetimes DataFrame (results :class:`SurvivalCurves`, :class:`EscapeRates` with ``.to_frame()`` and
  ``.plot(ax=)``, as for every function below)
- :func:`kappa_cmeasure` — κ from the c-measure of a run's section crossings, beside κ from P(t)
- :func:`transition_times` — τ0, τ1, τ2 of each dissipative point against its γ = 0 partner
- :func:`energy_decay` — ⟨E⟩(t) of the orbits inside and μ of E0·e^{−μγt}
- :func:`cmeasure_points`, :func:`cmeasure_distances` — section points of the c-measure, and their
  distances to a reference set against the box scale
- :func:`basin_measures` — exit-basin maps of a grid of ICs, basin shares, basin entropy, Wada test
- :func:`plot_survival`, :func:`plot_escape_rates` — draw on your matplotlib axes
- :class:`HenonHeiles` — the paper's system, with closed forms (E_c, saddles, channels)
- :func:`make_system`, :class:`DeclaredSystem` — any other system: a built-in by name or a potential V(x, y)
  as an expression, its E_c, exits, Ω and no-return radius derived (pass it, or its spec, as ``Scene(system=)``)
- :class:`HHScatterError` and its family (:mod:`hhscatter.errors`): :class:`ConfigError` (alias
  :class:`SceneError`), :class:`RunIntegrityError`, :class:`StudyError`, :class:`RunError`

``__version__`` is the installed distribution's version (``pyproject.toml`` is
its only source).
"""

import importlib

from hhscatter._version import __version__ as __version__  # re-exported

_EXPORTS = {
    "Scene": "scene.scene",
    "SectionWindow": "scene.recording",
    "Noise": "scene.noise",
    "SceneError": "errors",
    "HHScatterError": "errors",
    "ConfigError": "errors",
    "RunError": "errors",
    "StudyError": "errors",
    "RunIntegrityError": "errors",
    "load_scene": "scene.schema",
    "Grid": "scene.grid",
    "load_run": "scene.grid",
    "simulate": "run.runner",
    "read_lifetimes": "data.read",
    "read_sections": "data.read",
    "read_snapshots": "data.read",
    "survival": "api",
    "escape_rates": "api",
    "plot_survival": "api",
    "plot_escape_rates": "api",
    "SurvivalCurves": "api",
    "EscapeRates": "api",
    "kappa_cmeasure": "api",
    "transition_times": "api",
    "energy_decay": "api",
    "cmeasure_points": "api",
    "cmeasure_distances": "api",
    "basin_measures": "api",
    "HenonHeiles": "model",
    "make_system": "model",
    "DeclaredSystem": "model",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module 'hhscatter' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
