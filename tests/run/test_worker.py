"""The worker side of a run: every chunk gets the plan its run built once per point."""

import pickle

from hhscatter.run import worker
from hhscatter.run.runner import simulate
from hhscatter.scene.grid import Grid
from hhscatter.scene.scene import Scene

SCENE = Scene(energy=0.3, n=30, seed=3, chunk_size=10, t_max=50.0)


def test_a_run_builds_each_points_plan_once_and_hands_it_to_every_chunk(tmp_path, monkeypatch):
    built = []
    real = worker.plan_of

    def counted(scene, *a, **k):
        built.append(scene.energy)
        return real(scene, *a, **k)

    def rebuilt(*a, **k):
        raise AssertionError("a chunk rebuilt its scene and plan")

    monkeypatch.setattr(worker, "plan_of", counted)
    monkeypatch.setattr(worker, "_scene_and_plan", rebuilt)
    summary = simulate(Grid(SCENE, energies=(0.3, 0.35), gammas=(0.0,)), tmp_path / "g", workers=1, progress=False)
    assert summary.chunks_done == 6 and sorted(built) == [0.3, 0.35]


def test_a_packed_point_is_the_scene_and_its_plan():
    scene, plan = pickle.loads(worker.pack_point(SCENE))
    assert scene.result_hash() == SCENE.result_hash()
    assert plan.scheduler == "stream" and plan.model is scene.model and plan.t_max == 50.0
