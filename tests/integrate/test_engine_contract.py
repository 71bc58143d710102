"""The engine's declared contracts: lane rules as an abstract base, handlers bound by each event's rule."""

import numpy as np
import pytest

from hhscatter.integrate import engine, events
from hhscatter.integrate.plan import plan_of
from hhscatter.scene.scene import Follow, Scene, SectionWindow


def test_a_scheduler_must_supply_the_integrator_access():
    class Incomplete(engine.LaneRules):
        def elapsed(self, lane):
            return 0.0

    with pytest.raises(TypeError, match="abstract"):
        Incomplete()
    assert {"elapsed", "state4", "set_gate", "set_clock", "record", "release"} == engine.LaneRules.__abstractmethods__


@pytest.mark.parametrize(
    "scene",
    [
        Scene(energy=0.3, n=4, gamma=0.01, sections=SectionWindow(t_from=1.0, t_to=5.0)),
        Scene(energy=0.3, n=4, follow=Follow(radii=(1.2, 2.0))),
        Scene(energy=0.3, n=4),
    ],
)
def test_every_event_of_a_scene_has_the_handler_of_its_rule(scene):
    specs = plan_of(scene).events
    assert specs and all(s.rule in events.RULES for s in specs)

    class Probe(engine.LaneRules):
        elapsed = state4 = set_gate = set_clock = record = release = None

    rules = Probe()
    for spec in specs:
        h = rules.handler(spec)
        if spec.rule == "radius":
            assert h.func == rules.on_radius and h.args == (spec.index,)
        else:
            assert h == getattr(rules, f"on_{spec.rule}")
    radii = [s for s in specs if s.rule == "radius"]
    assert [s.index for s in radii] == list(range(len(radii)))


def test_an_event_with_an_unknown_rule_is_refused():
    with pytest.raises(ValueError, match="rule must be one of"):
        events.EventSpec("bounce", 0, lambda s: s.r2, "no such rule")


def test_the_bound_handlers_run_a_chunk_like_before():
    """Binding by rule is what the engine runs: a follow scene (radius handlers with their index) ends as usual."""
    scene = Scene(energy=0.3, n=8, seed=2, follow=Follow(radii=(1.0, 2.0)), t_max=200.0)
    from hhscatter.scene.ics import region_ics

    res = engine.run_chunk(scene, region_ics(scene, 0, 8), np.arange(8))
    assert len(res.lifetimes["traj_id"]) == 8
    assert set(np.unique(res.crossings["radius"])) <= {1.0, 2.0, scene.r_esc}
