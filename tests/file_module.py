"""Load a Python file that is not an importable module (a docs hook, a tool script) as a module, for tests."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path


def load_file(path: Path, name: str):
    """The module defined by the file ``path``, registered in ``sys.modules`` as ``name``."""
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod
