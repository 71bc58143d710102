"""Run directories: the scene a run was written with."""

from __future__ import annotations

import json

from hhscatter.data.store import Store


def run_scene(run) -> dict:
    """The scene a run directory was written with, as a dict (``scene.json``; infinities decoded).

    Raises ValueError if ``run`` holds no ``scene.json`` (not a run of :func:`hhscatter.simulate`).
    """
    from hhscatter.run.plan import SCENE_FILE, _decode  # deferred: pydantic loads on first use

    store = Store(run)
    if not store.exists(SCENE_FILE):
        raise ValueError(f"{run}: no {SCENE_FILE}: not a run directory written by hhscatter.simulate")
    return _decode(json.loads(store.read_text(SCENE_FILE))["scene"])
