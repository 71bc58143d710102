"""The scheduler contract and registry, checked with the toy scheduler of the docs page "Adding a scheduler"
(its code blocks are run as they stand)."""

import re
from pathlib import Path

import numpy as np
import pytest

from hhscatter.integrate.chunk import run_chunk
from hhscatter.integrate.engine import CENSORED, ESCAPED
from hhscatter.integrate.plan import plan_of
from hhscatter.integrate.schedulers import SCHEDULERS, Scheduler, register
from hhscatter.scene.ics import region_ics
from hhscatter.scene.noise import Noise
from hhscatter.scene.scene import Scene

PAGE = Path(__file__).resolve().parents[2] / "docs" / "concepts" / "schedulers.md"


@pytest.fixture
def guide():
    """The namespace of the page's code blocks, run in order (the toy registers itself; removed afterwards)."""
    blocks = re.findall(r"```python\n(.*?)```", PAGE.read_text(), flags=re.S)
    assert len(blocks) == 2
    ns = {}
    try:
        for code in blocks:
            exec(compile(code, str(PAGE), "exec"), ns)
        yield ns
    finally:
        SCHEDULERS.pop("one-by-one", None)


def test_the_guides_scheduler_registers_and_runs_as_the_stream(guide):
    """The toy of the guide: registered, never chosen for a scene that does not name it, and its tables those of
    the stream on the same orbits (outcomes, escape times bit for bit; censored at t_max)."""
    assert SCHEDULERS["one-by-one"] is guide["OneByOne"]
    scene, res = guide["scene"], guide["res"]
    assert plan_of(scene).scheduler == "stream"
    ics = region_ics(scene, 0, scene.n)
    ref = run_chunk(scene, ics, np.arange(scene.n)).lifetimes
    toy = res.lifetimes
    assert set(ref["outcome"]) == {ESCAPED, CENSORED}
    assert (toy["outcome"] == ref["outcome"]).all()
    assert (toy["t_end"] == ref["t_end"]).all()
    esc = ref["outcome"] == ESCAPED
    assert (toy["e_end"][esc] == ref["e_end"][esc]).all()
    assert toy["e_end"][~esc] == pytest.approx(ref["e_end"][~esc], rel=1e-13)


def test_plans_choose_the_built_in_schedulers():
    assert plan_of(Scene(energy=0.3, n=1)).scheduler == "stream"
    assert plan_of(Scene(energy=0.3, n=1, snapshots=(0.0, 1.0))).scheduler == "epochs"
    noisy = Scene(energy=0.3, n=1, gamma=1.0, noise=Noise(temperature=0.05))
    assert plan_of(noisy).scheduler == "noise"
    assert plan_of(noisy).kind.deterministic is False


def test_the_registry_refuses_what_is_not_a_scheduler_and_plans_an_unknown_name():
    class Nameless(Scheduler):
        def run(self):
            return 0, 0, ()

    with pytest.raises(TypeError, match="named subclass of Scheduler"):
        register(Nameless)
    with pytest.raises(TypeError, match="named subclass of Scheduler"):
        register(object)
    with pytest.raises(ValueError, match="scheduler must be one of"):
        plan_of(Scene(energy=0.3, n=1), scheduler="no such")
