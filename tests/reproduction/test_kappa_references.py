"""The κ references read from the escape-rate study's numbers JSON."""

import pytest

from hhscatter.reproduction.kappa_references import kappa_references


def test_kappa_references_read_both_routes_and_name_a_missing_list():
    doc = {
        "kappa_energy": [{"energy": 0.25, "kappa": 0.097, "kappa_err": 0.002}],
        "cmeasure": {"E0.25": {"energy": 0.25, "kappa_cm": {"value": 0.0972, "err": 0.0002}}, "note": "text"},
    }
    assert kappa_references(doc) == ({0.25: (0.097, 0.002)}, {0.25: (0.0972, 0.0002)})
    with pytest.raises(KeyError, match="kappa_energy"):
        kappa_references({"cmeasure": {}})
