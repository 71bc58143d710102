"""Run directories: the scene a run was written with."""

from __future__ import annotations

import json

from hhscatter.api import checks
from hhscatter.data.store import Store


def run_scene(run) -> dict:
    """The scene a run directory was written with, as a dict (``scene.json``; infinities decoded).

    Raises ConfigError (a ValueError) if ``run`` is not a path or holds no ``scene.json`` (not a run of
    :func:`hhscatter.simulate`).
    """
    from hhscatter.run.plan import SCENE_FILE, _decode  # deferred: pydantic loads on first use

    checks.run_dir(run)
    store = Store(run)
    return _decode(json.loads(store.read_text(SCENE_FILE))["scene"])
