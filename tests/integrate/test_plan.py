"""The plan: frozen once, pickled as it is (derived values included), integrated alike after a round trip."""

import pickle

import numpy as np
import pytest

from hhscatter.integrate import events
from hhscatter.integrate.chunk import run_chunk
from hhscatter.integrate.plan import plan_of
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Follow, Scene, SectionWindow

SCENES = [
    Scene(energy=0.3, n=12, seed=5, gamma=0.01, t_max=60.0, sections=SectionWindow(t_from=5.0)),
    Scene(energy=0.3, n=12, seed=6, t_max=60.0, follow=Follow(radii=(1.2, 2.0))),
    Scene(energy=0.3, n=12, seed=7, gamma=0.01, t_max=30.0, snapshots=(0.0, 2.5, 10.0)),
    Scene(energy=0.3, n=12, seed=8, t_max=60.0, system={"potential": "x**2/2 + y**2/2 + x**2*y - y**3/3"}),
]


@pytest.mark.parametrize("scene", SCENES, ids=["sections", "follow", "snapshots", "declared"])
def test_a_plan_pickles_as_it_is_and_integrates_alike(scene, monkeypatch):
    plan = plan_of(scene)
    packed = pickle.dumps(plan)

    def derived_again(*a, **k):
        raise AssertionError("the plan was derived again when unpickled")

    for name in ("scene_events", "layout", "clock_targets", "far_radius"):
        monkeypatch.setattr(events, name, derived_again)
    back = pickle.loads(packed)
    monkeypatch.undo()
    assert back.scheduler == plan.scheduler and back.layout == plan.layout
    assert back.clock_targets == plan.clock_targets and back.two_phase == plan.two_phase
    assert [(e.name, e.direction, e.rule, e.index) for e in back.events] == [
        (e.name, e.direction, e.rule, e.index) for e in plan.events
    ]
    ics = region_ics(scene, 0, scene.n)
    a = run_chunk(plan, ics, np.arange(scene.n)).tables()
    b = run_chunk(back, ics, np.arange(scene.n)).tables()
    assert a.keys() == b.keys()
    for name in a:
        for col in a[name]:
            assert np.array_equal(np.asarray(a[name][col]), np.asarray(b[name][col])), (name, col)
