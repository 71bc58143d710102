"""A pole of the potential where orbits move is refused before any work, also one that no grid point hits."""

from __future__ import annotations

import pytest

import hhscatter
from hhscatter.cli import main

HH = "0.5*(x**2 + y**2) + x**2*y - y**3/3"


@pytest.mark.parametrize(
    ("term", "where"),
    [
        ("1e-30/((x - 0.0123)**2 + (y - 1.3)**2) - 1e-30/(0.0123**2 + 1.3**2)", "(0.0123, 1.3)"),  # a point pole
        ("1e-30/(x**2 + y**2 - 1.4641)**2 - 1e-30/1.4641**2", "inside r ≤ 1.5"),  # poles on the circle r = 1.21
    ],
)
def test_a_pole_inside_r_esc_is_refused_before_any_work(tmp_path, capsys, term, where):
    args = ["simulate", "--system", f"{HH} + {term}", "--energy", "0.3", "-n", "20", "--t-max", "5"]
    assert main([*args, "--workers", "1", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "system.potential: V or its gradient is not finite at" in err and where in err, err
    assert "Traceback" not in err and list(tmp_path.iterdir()) == []


def test_a_smooth_non_polynomial_potential_is_taken():
    sc = hhscatter.Scene(energy=0.3, n=10, system={"potential": f"{HH} + 1e-3*(1 - exp(-(x**2 + y**2)))"})
    assert sc.model.nonfinite_point(sc.r_esc) is None
