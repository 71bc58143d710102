"""Configurations of ``make bench`` / ``make stress``: ``benchmarks/<name>.toml`` with ``[scale.<s>.*]`` overrides."""

from __future__ import annotations

import copy
import os
import tomllib
from pathlib import Path

SCALES = ("full", "tiny")


def bench_root() -> Path:
    """This folder, ``benchmarks/``: its ``<name>.toml`` configurations, its ``out/`` results."""
    return Path(__file__).resolve().parent


def _merge(base, over):
    out = copy.deepcopy(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else copy.deepcopy(v)
    return out


def load_config(name: str, scale: str = "full", root=None) -> dict:
    """The configuration ``<root>/<name>.toml`` (default root: ``benchmarks/``) merged with its scale's overrides.

    Raises ValueError naming ``scale`` for an unknown scale, FileNotFoundError for a missing file.
    """
    if scale not in SCALES:
        raise ValueError(f"scale must be one of {SCALES}, got {scale!r}")
    path = Path(root or bench_root()) / f"{name}.toml"
    if not path.exists():
        raise FileNotFoundError(f"config not found: {path}")
    with open(path, "rb") as fh:
        cfg = tomllib.load(fh)
    scales = cfg.pop("scale", {})
    if scale != "full":
        cfg = _merge(cfg, scales.get(scale, {}))
    cfg["_scale"] = scale
    # relative to the repository, so a summary reads the same on every machine
    cfg["_path"] = f"benchmarks/{name}.toml" if root is None else str(path)
    return cfg


def out_dir(name: str, scale: str, root=None) -> Path:
    """The results folder ``<root>/out/<name>/<scale>/`` (default root: ``benchmarks/``), created."""
    p = Path(root or bench_root()) / "out" / name / scale
    p.mkdir(parents=True, exist_ok=True)
    return p


def machine_note() -> str:
    """One line on the machine's state: cores and load average (timings are taken under load)."""
    try:
        la = os.getloadavg()
        load = f"load average {la[0]:.2f}, {la[1]:.2f}, {la[2]:.2f}"
    except OSError:
        load = "load average unknown"
    return f"{os.cpu_count()} cores, {load}"
