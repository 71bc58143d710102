"""The [noise] table of a scene: validated like every input (exit 2 naming the key, nothing written), part of the
scene's hash only when present (every scene without noise keeps its hash)."""

from __future__ import annotations

from pathlib import Path

import pytest

from hhscatter.cli import main
from hhscatter.errors import ConfigError
from hhscatter.scene.scene import Noise, Scene, scene_from_dict

BAD_NOISE = [
    ("energy = 0.1\nn = 40", "temperature = 0.05", "noise.temperature is a heat bath: it needs drag gamma > 0"),
    (
        "energy = 0.1\nn = 40\ngamma = 1.0",
        "sigma = 0.1",
        "noise.sigma is noise without drag (gamma = 0), got gamma = 1",
    ),
    ("energy = 0.1\nn = 40\ngamma = 1.0", "temperature = 0.05\nsigma = 0.1", "noise needs exactly one of temperature"),
    ("energy = 0.1\nn = 40\ngamma = 1.0", "kick = 0.1", "noise needs exactly one of temperature"),
    ("energy = 0.1\nn = 40\ngamma = 1.0", "temperature = -0.05", "noise.temperature must be > 0, got -0.05"),
    ("energy = 0.1\nn = 40\ngamma = 1.0", 'temperature = "0.05"', "[noise] temperature must be a number, got '0.05'"),
    ("energy = 0.1\nn = 40\ngamma = 1.0", "temprature = 0.05", "[noise] unknown key 'temprature' (did you mean"),
    ("energy = 0.1\nn = 40\ngamma = 1.0", "temperature = 0.05\nkick = 0.6", "noise.kick must be ≤ 0.5 min(1/ω, 1/γ)"),
    ("energy = 0.1\nn = 40\ngamma = 1.0\nr_far = 5.0", "temperature = 0.05", "r_far is not read with noise"),
    (
        "energy = 0.1\nn = 40\ngamma = 1.0",
        "temperature = 0.05\n[snapshots]\ntimes = [1.0]",
        "snapshots is not available with noise: a noise scene records lifetimes only",
    ),
]


@pytest.mark.parametrize("scene, noise, message", BAD_NOISE)
def test_bad_noise_exits_2_naming_the_key_and_writes_nothing(scene, noise, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scene.toml").write_text(f"[scene]\n{scene}\n[noise]\n{noise}\n")
    rc = main(["simulate", "scene.toml", "--out", "run", "--workers", "1"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and message in err, err
    assert "Traceback" not in err
    assert sorted(p.name for p in Path(tmp_path).iterdir()) == ["scene.toml"]


def test_noise_with_sections_is_refused_by_the_scene_itself():
    from hhscatter.scene.scene import SectionWindow

    with pytest.raises(ConfigError, match="sections is not available with noise"):
        Scene(energy=0.3, n=10, noise=Noise(sigma=0.1), sections=SectionWindow())
    with pytest.raises(ConfigError, match="noise.temperature needs the linear drag law"):
        Scene(
            energy=0.3,
            n=10,
            gamma=0.1,
            noise=Noise(temperature=0.05),
            system={"name": "henon_heiles", "dissipation": "quadratic"},
        )


def test_scenes_without_noise_keep_their_hashes():
    """Hashes computed by the code before the noise table existed."""
    assert (
        Scene(energy=0.3, n=100, gamma=0.01, seed=1).result_hash()
        == "2d7b6983a42735db77604453b888548eea30e7a95e964f47e99c2e5992f724b8"
    )
    assert (
        Scene(energy=0.25, n=100, seed=2, t_max=300).result_hash()
        == "bc9decd30f200d1b8b7cbf6394559a00b659c962bb803d8ae9c594f1aaa084a3"
    )
    assert "noise" not in Scene(energy=0.3, n=10).to_dict()


def test_noise_is_part_of_the_hash_and_round_trips():
    base = Scene(energy=0.1, n=10, gamma=1.0, noise=Noise(temperature=1 / 36))
    assert base.to_dict()["noise"] == {"temperature": 1 / 36}
    assert base.result_hash() != base.replace(noise=Noise(temperature=1 / 30)).result_hash()
    assert base.result_hash() != base.replace(noise=Noise(temperature=1 / 36, kick=0.05)).result_hash()
    again = scene_from_dict(base.to_dict())
    assert again == base and again.result_hash() == base.result_hash()


def test_a_noise_scene_may_start_below_the_saddle_energy():
    """Noise lifts an orbit over the saddles: E0 ≤ E_c is a valid start (a thermal well), not a settled orbit."""
    s = Scene(energy=0.05, n=10, gamma=1.0, noise=Noise(temperature=0.05))
    assert s.energy < s.model.critical_energy
    with pytest.raises(ConfigError, match="energy must be > E_c"):
        Scene(energy=0.05, n=10, gamma=1.0)


def test_the_default_kick_resolves_the_shortest_time_scale():
    s = Scene(energy=0.1, n=10, gamma=4.0, noise=Noise(temperature=0.05))
    assert s.kick_interval == pytest.approx(0.1 / 4.0)
    s = Scene(energy=0.3, n=10, noise=Noise(sigma=0.05))
    assert s.kick_interval == pytest.approx(0.1) and s.noise_strength == 0.05
