"""A noise scene is bounded by its number of kicks per orbit, t_max / h: beyond KICKS_PER_ORBIT_MAX it is refused
before any work, naming the key and what the run would cost."""

from __future__ import annotations

import re

import pytest

import hhscatter
from hhscatter.cli import main
from hhscatter.scene.noise import KICKS_PER_ORBIT_MAX


@pytest.mark.parametrize(
    ("kick", "kicks"), [(1e-9, "5e+12"), (1e-300, "5e+303"), (5000 / (KICKS_PER_ORBIT_MAX + 10), "1e+07")]
)
def test_a_kick_interval_too_short_for_t_max_is_refused_with_its_cost(kick, kicks):
    with pytest.raises(
        hhscatter.ConfigError,
        match=rf"noise.kick: t_max / noise.kick = 5000 / .* = {re.escape(kicks)} kicks per orbit, more than 1e\+07 \(the 10 orbits would take ≈ .* CPU-hours",
    ):
        hhscatter.Scene(energy=0.3, n=10, noise=hhscatter.Noise(sigma=0.01, kick=kick))


def test_the_limit_itself_is_taken():
    sc = hhscatter.Scene(energy=0.3, n=10, noise=hhscatter.Noise(sigma=0.01, kick=5000 / KICKS_PER_ORBIT_MAX))
    assert sc.kick_interval == 5000 / KICKS_PER_ORBIT_MAX


def test_a_long_t_max_at_the_default_kick_is_refused_naming_t_max():
    with pytest.raises(
        hhscatter.ConfigError,
        match=r"^t_max: t_max / the kick interval 0.1 min\(1/ω, 1/γ\) = 2e\+06 / 0.1 = 2e\+07 kicks",
    ):
        hhscatter.Scene(energy=0.1, n=10, gamma=1.0, t_max=2e6, noise=hhscatter.Noise(temperature=0.03))


def test_cli_refuses_a_scene_file_kick_before_any_work(tmp_path, capsys):
    scene = tmp_path / "noisy.toml"
    scene.write_text("[scene]\nenergy = 0.3\nn = 10\n[noise]\nsigma = 0.01\nkick = 1e-9\n")
    assert main(["simulate", str(scene), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "noise.kick: t_max / noise.kick = 5000 / 1e-09 = 5e+12 kicks per orbit" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["noisy.toml"]
