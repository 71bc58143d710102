"""The package's layers: no import circle, and every import points down the declared layers.

The import graph is read from the source with :mod:`ast` by tools/layer_metrics.py (module-level and
function-level imports alike: a deferred import hides a circle from Python, not from the design); the layers
and what each may import are ``LAYERS`` there (docs/api/index.md shows the same table).
"""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("layer_metrics", ROOT / "tools" / "layer_metrics.py")
lm = importlib.util.module_from_spec(spec)
spec.loader.exec_module(lm)

M = lm.measure(ROOT, "hhscatter", [])


def test_no_import_circle():
    assert M["circles"] == []


def test_imports_point_down_the_layers():
    assert lm.layer_violations(M["graph"]) == []


def test_every_function_level_import_says_why_it_is_deferred():
    """A deferred import avoids a heavy import at start-up (pandas, pyarrow, heyoka, ...): its comment says which."""
    assert M["function_level_imports_without_reason"] == []


def test_every_module_is_in_a_declared_layer():
    layers = {lm.layer_of(m) for m in M["graph"]}
    assert layers <= set(lm.LAYERS) | lm.TOP, layers - set(lm.LAYERS) - lm.TOP


def test_the_check_sees_an_upward_import():
    graph = {
        "hhscatter.data.tables": {"hhscatter.analysis.survival.kaplan_meier"},
        "hhscatter.analysis.survival.kaplan_meier": set(),
        "hhscatter.cli": {"hhscatter.publish.report"},
    }
    assert lm.layer_violations(graph) == [
        "hhscatter.data.tables -> hhscatter.analysis.survival.kaplan_meier (layer data may not import layer analysis.survival)"
    ]


def test_the_check_sees_an_upward_import_between_analysis_subpackages():
    graph = {
        "hhscatter.analysis.survival.long_time": {"hhscatter.analysis.dissipative.decay"},
        "hhscatter.analysis.dissipative.decay": {"hhscatter.analysis.survival.kaplan_meier"},
        "hhscatter.analysis.survival.kaplan_meier": {"hhscatter.analysis.stats.intervals"},
        "hhscatter.analysis.geometry.channels": {"hhscatter.reproduction.fig2"},
        "hhscatter.analysis.stats.intervals": set(),
    }
    assert lm.layer_violations(graph) == [
        "hhscatter.analysis.geometry.channels -> hhscatter.reproduction.fig2 "
        "(layer analysis.geometry may not import layer reproduction)",
        "hhscatter.analysis.survival.long_time -> hhscatter.analysis.dissipative.decay "
        "(layer analysis.survival may not import layer analysis.dissipative)",
    ]


def test_analysis_subpackages_are_layers_of_their_own():
    assert lm.layer_of("hhscatter.analysis.geometry.basins") == "analysis.geometry"
    assert lm.layer_of("hhscatter.analysis") == "analysis" and lm.layer_of("hhscatter._exports") == "_exports"
    assert lm.layer_of("hhscatter.reproduction.claims.kappa") == "reproduction"


def test_the_engine_imports_neither_scene_nor_model():
    """The engine reads a scene only through its plan (hhscatter.integrate.plan), which carries the system."""
    engine = {m: deps for m, deps in M["graph"].items() if lm.layer_of(m) == "integrate"}
    assert engine and not lm.LAYERS["integrate"] & {"scene", "model"}
    assert [(m, d) for m, deps in engine.items() for d in deps if lm.layer_of(d) in ("scene", "model")] == []


def test_heyoka_is_imported_only_by_the_engine():
    assert lm.confined_violations(M["external"]) == []
    importers = {lm.layer_of(m) for m, deps in M["external"].items() if "heyoka" in deps}
    assert importers == {"integrate"}


def test_the_check_sees_heyoka_imported_outside_the_engine():
    external = {"hhscatter.model.base": {"numpy", "heyoka"}, "hhscatter.integrate.batch": {"heyoka"}}
    assert lm.confined_violations(external) == ["hhscatter.model.base -> heyoka (only integrate may import it)"]
