"""A scene's system as data: the [system] table, its canonical form, the hash, the drag law."""

import json
import math

import numpy as np
import pytest
from scipy import integrate

from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles
from hhscatter.model.spec import canonical_spec
from hhscatter.scene.scene import Scene, scene_from_dict
from hhscatter.scene.schema import load_scene


def test_henon_heiles_with_linear_drag_is_the_scene_without_a_system():
    """A Hénon–Heiles spec with linear drag folds into ω, λ: same scene, same hash as before systems existed."""
    plain = Scene(energy=0.3, n=100, gamma=0.01)
    named = Scene(energy=0.3, n=100, gamma=0.01, system={"name": "henon_heiles"})
    assert named.system is None and named.result_hash() == plain.result_hash()
    scaled = Scene(energy=0.3, n=100, system={"name": "henon_heiles", "params": {"omega": 1.0, "lam": 2.0}})
    assert (scaled.omega, scaled.lam, scaled.system) == (1.0, 2.0, None)
    assert scaled.result_hash() == Scene(energy=0.3, n=100, lam=2.0).result_hash()
    assert "system" not in plain.to_dict()


def test_quadratic_drag_is_another_scene_and_round_trips():
    quad = Scene(energy=0.3, n=100, gamma=0.01, system={"name": "henon_heiles", "dissipation": "quadratic"})
    assert quad.system == {"name": "henon_heiles", "params": {"lam": 1.0, "omega": 1.0}, "dissipation": "quadratic"}
    assert quad.model.dissipation == "quadratic"
    assert quad.result_hash() != Scene(energy=0.3, n=100, gamma=0.01).result_hash()
    again = scene_from_dict(json.loads(quad.to_json()))
    assert again.result_hash() == quad.result_hash() and again.system == quad.system


@pytest.mark.parametrize(
    "spec, message",
    [
        ({"name": "henon_heiles", "potential": "x**2"}, "exactly one of 'name'"),
        ({}, "exactly one of 'name'"),
        ({"name": "henon_heiles", "colour": 1}, "unknown [system] keys: ['colour']"),
        ({"name": "henon_heiles", "dissipation": "cubic"}, "system.dissipation must be one of"),
        ({"name": "henon_heiles", "params": {"lam": "one"}}, "system.params.lam must be a finite number"),
        ({"name": "henon_heiles", "params": {"mu": 1.0}}, "henon_heiles has parameters ['lam', 'omega'], got ['mu']"),
        ({"name": "henon_heiles", "params": {"lam": -1.0}}, "lam must be a finite number > 0"),
    ],
)
def test_bad_system_specs_name_the_key(spec, message):
    with pytest.raises(ConfigError, match=None) as exc:
        Scene(energy=0.3, n=10, system=spec)
    assert message in str(exc.value)


def test_omega_and_lam_with_a_system_are_refused():
    with pytest.raises(ConfigError, match="system.params.omega"):
        Scene(energy=0.3, n=10, omega=2.0, system={"name": "henon_heiles", "dissipation": "quadratic"})


def test_scene_file_system_table(tmp_path):
    f = tmp_path / "scene.toml"
    f.write_text(
        '[scene]\nenergy = 0.3\nn = 10\ngamma = 0.01\n[system]\nname = "henon_heiles"\n'
        'dissipation = "quadratic"\n[system.params]\nlam = 1.0\n'
    )
    s = load_scene(f)
    assert s.system["dissipation"] == "quadratic" and s.model.lam == 1.0
    f.write_text('[scene]\nenergy = 0.3\nn = 10\n[system]\nname = "henon_heiles"\ndrag = "linear"\n')
    with pytest.raises(ConfigError, match="drag"):
        load_scene(f)
    f.write_text('[scene]\nenergy = 0.3\nn = 10\n[system]\nname = "henon_heiles"\n[system.params]\nlam = "1"\n')
    with pytest.raises(ConfigError, match="lam"):
        load_scene(f)


def test_canonical_spec_writes_every_parameter_as_a_float():
    assert canonical_spec({"potential": " x**2 + y**2 ", "params": {"b": 2, "a": 1}}) == {
        "potential": "x**2 + y**2",
        "params": {"a": 1.0, "b": 2.0},
        "dissipation": "linear",
    }


def test_default_escape_radius_comes_from_the_system():
    """Hénon–Heiles keeps its 1.5 (every existing hash); the contract's default is max(1.5 r_s, R(E))."""
    assert Scene(energy=0.3, n=10).r_esc == 1.5
    hh = HenonHeiles()
    assert hh.no_return_radius(0.3) == pytest.approx(math.sqrt(1.8), rel=1e-15)
    assert hh.no_return_radius(hh.critical_energy) == pytest.approx(1.0, rel=1e-15)


def _quadratic_rhs(t, s, gamma):
    x, y, px, py = s
    sp = math.hypot(px, py)
    return [px, py, -x - 2 * x * y - gamma * sp * px, -y - (x * x - y * y) - gamma * sp * py]


@pytest.mark.parametrize("dissipation", ["linear", "quadratic"])
def test_drag_laws_against_an_independent_integrator(dissipation):
    """heyoka's system of either drag law against scipy's DOP853 on the same equations, written out by hand."""
    import heyoka as hy

    gamma = 0.05
    hh = HenonHeiles(dissipation=dissipation)
    ta = hy.taylor_adaptive(hh.equations(hy, hy.par[0]), [0.1, 0.2, 0.3, -0.2], pars=[gamma], tol=1e-15)
    ta.propagate_until(10.0)

    def rhs(t, s):
        if dissipation == "quadratic":
            return _quadratic_rhs(t, s, gamma)
        x, y, px, py = s
        return [px, py, -x - 2 * x * y - gamma * px, -y - (x * x - y * y) - gamma * py]

    ref = integrate.solve_ivp(rhs, (0.0, 10.0), [0.1, 0.2, 0.3, -0.2], method="DOP853", rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(ta.state, ref.y[:, -1], rtol=0, atol=1e-10)
    # the energy only falls: dE/dt = −γ|p|² (linear) or −γ|p|³ (quadratic)
    assert hh.energy(*ta.state) < hh.energy(0.1, 0.2, 0.3, -0.2)


def test_exits_and_critical_energy_can_be_given_and_are_checked():
    spec = {
        "potential": "0.5*(x**2 + y**2) - eps*x**2*y**2",
        "params": {"eps": 0.25},
        "exits": [[2**0.5, 2**0.5], [-(2**0.5), 2**0.5], [-(2**0.5), -(2**0.5)], [2**0.5, -(2**0.5)]],
    }
    s = Scene(energy=1.5, n=10, system=spec)
    assert len(s.model.exits) == 4 and s.model.critical_energy == pytest.approx(1.0, rel=1e-12)
    assert s.system["exits"][0] == [2**0.5, 2**0.5]
    with pytest.raises(ConfigError, match="system.exits must be a list"):
        Scene(energy=1.5, n=10, system=dict(spec, exits=[[1.0]]))
    with pytest.raises(ConfigError, match="cannot be given for the built-in"):
        Scene(energy=1.5, n=10, system={"name": "contopoulos", "critical_energy": 1.0})
