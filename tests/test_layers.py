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
