"""tools/layer_metrics.py measures the layering on a synthetic package with known answers."""

import importlib.util
from pathlib import Path

spec = importlib.util.spec_from_file_location(
    "layer_metrics", Path(__file__).resolve().parents[2] / "tools" / "layer_metrics.py"
)
lm = importlib.util.module_from_spec(spec)
spec.loader.exec_module(lm)


def _pkg(tmp_path: Path) -> Path:
    p = tmp_path / "pkg"
    (p / "sub").mkdir(parents=True)
    (p / "__init__.py").write_text("from . import a\n")
    (p / "sub" / "__init__.py").write_text("")
    # a -> b at module level, b -> a inside a function: one circle, one deferred own import
    (p / "a.py").write_text("from . import b\n\ndef f(study):\n    return float(study.param('x'))\n")
    (p / "b.py").write_text("def g():\n    from .a import f\n    import json\n    return f\n")
    # c -> sub.d -> c: a second circle through a subpackage; e imports a without a circle
    (p / "c.py").write_text("from .sub.d import h\n")
    (p / "sub" / "d.py").write_text("from ..c import h\n\ndef h():\n" + "    x = 1\n" * 85 + "    return x\n")
    (p / "e.py").write_text("from pkg.a import f\n")
    return tmp_path


def test_metrics_on_a_known_package(tmp_path):
    m = lm.measure(_pkg(tmp_path), "pkg", [])
    assert sorted(m["circles"]) == [["pkg.a", "pkg.b"], ["pkg.c", "pkg.sub.d"]]
    assert len(m["function_level_imports"]) == 2  # `from .a import f` and `import json`
    assert len(m["function_level_own_imports"]) == 1
    assert len(m["param_casts"]) == 1
    assert [n for n, _ in m["long_functions"]] == [87]


def test_no_circle_without_a_back_edge(tmp_path):
    root = _pkg(tmp_path)
    (root / "pkg" / "b.py").write_text("def g():\n    return 1\n")
    (root / "pkg" / "sub" / "d.py").write_text("def h():\n    return 1\n")
    assert lm.measure(root, "pkg", [])["circles"] == []


def test_casts_of_study_parameters_are_told_from_other_casts(tmp_path):
    p = tmp_path / "pkg"
    p.mkdir()
    (p / "__init__.py").write_text("")
    (p / "s.py").write_text(
        "def f(study, row):\n"
        "    a = float(study.param('x'))\n"  # a cast: counted
        "    b = int(study.params.n)\n"  # counted
        "    c = [float(v) for v in study.params.e]\n"  # element-wise: counted
        "    d = tuple(float(v) for v in study.params.w)\n"  # counted
        "    e = list(map(float, study.params.e))\n"  # counted
        "    g = float(row['mu'])\n"  # a DataFrame row: not a study parameter
        "    h = study.params.e\n"  # typed, no cast
        "    return a, b, c, d, e, g, h\n"
    )
    m = lm.measure(tmp_path, "pkg", [])
    assert sorted(int(w.rsplit(":", 1)[1]) for w in m["param_casts"]) == [2, 3, 4, 5, 6]
