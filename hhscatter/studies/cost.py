"""What a study stage costs: wall time, CPU time, orbits integrated and peak memory.

``meter() -> context manager`` yields a :class:`StageCost` whose fields are
filled when the block ends:

* ``wall_s`` — elapsed wall-clock seconds;
* ``cpu_s`` — user + system CPU seconds of this process *and* of every child
  process it waited for (the runner's pool workers are spawned per run and
  joined, so their CPU time is included);
* ``rss_self_mb`` / ``rss_children_mb`` — peak resident set size of this
  process and of the largest child (MB), from ``getrusage`` (Linux reports KB).
  These are per-process peaks: the whole-job peak is at most their sum times the
  number of workers.

:func:`record` writes one invocation of a stage to ``out/<scale>/cost.json``
(a simulation interrupted and resumed has several invocations, their costs add
up; analyze and plot start over, so their last invocation replaces the earlier);
:func:`totals` sums a cost document per stage and :func:`summary` over the
stages. The numbers are measurements of a
shared machine: wall time depends on the load, CPU time much less.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from hhscatter.studies.jsonio import write_json_atomic

COST_FILE = "cost.json"
_KB = 1024.0 if sys.platform != "darwin" else 1024.0 * 1024.0  # ru_maxrss unit: KB on Linux, bytes on macOS


@dataclass
class StageCost:
    """One invocation of a stage: ``wall_s``, ``cpu_s`` (s), ``orbits``, ``rss_*_mb`` (MB), ``started`` (UTC)."""

    stage: str
    wall_s: float = 0.0
    cpu_s: float = 0.0
    orbits: int = 0
    chunks_resumed: int = 0
    rss_self_mb: float = 0.0
    rss_children_mb: float = 0.0
    cores: int = field(default_factory=lambda: os.cpu_count() or 1)
    workers: int | None = None
    started: str = ""
    completed: bool = False


def _cpu(who) -> float:
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


@contextmanager
def meter(stage: str, workers=None):
    """meter(stage, workers=None) -> context manager yielding a StageCost filled at exit (also on error)."""
    cost = StageCost(stage=stage, workers=workers, started=datetime.now(UTC).isoformat(timespec="seconds"))
    t0 = time.perf_counter()
    c0 = _cpu(resource.RUSAGE_SELF) + _cpu(resource.RUSAGE_CHILDREN)
    try:
        yield cost
    finally:
        cost.wall_s = time.perf_counter() - t0
        cost.cpu_s = _cpu(resource.RUSAGE_SELF) + _cpu(resource.RUSAGE_CHILDREN) - c0
        cost.rss_self_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * _KB / 2**20
        cost.rss_children_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * _KB / 2**20


def record(out: Path, cost: StageCost) -> Path:
    """record(out, cost) -> path of ``out/cost.json`` after appending ``cost`` to its stage's invocations."""
    path = Path(out) / COST_FILE
    doc = json.loads(path.read_text()) if path.exists() else {}
    if cost.stage != "simulate" or (cost.chunks_resumed == 0 and cost.orbits > 0):
        # analyze and plot start over each time; a simulation that resumed nothing is fresh: either way the
        # earlier invocations measured work that is no longer part of the outputs
        doc.pop(cost.stage, None)
    doc.setdefault(cost.stage, []).append(asdict(cost))
    write_json_atomic(path, doc)
    return path


def totals(doc: dict) -> dict:
    """totals(cost document) -> {stage: {wall_s, cpu_s, orbits, rss_self_mb, rss_children_mb, invocations}}.

    Times and orbits add over invocations; the memory peaks are the largest seen.
    """
    out = {}
    for stage, runs in doc.items():
        if not isinstance(runs, list) or not runs:
            continue
        out[stage] = {
            "wall_s": sum(r["wall_s"] for r in runs),
            "cpu_s": sum(r["cpu_s"] for r in runs),
            "orbits": sum(r.get("orbits", 0) for r in runs),
            "rss_self_mb": max(r["rss_self_mb"] for r in runs),
            "rss_children_mb": max(r["rss_children_mb"] for r in runs),
            "invocations": len(runs),
        }
    return out


def summary(doc: dict) -> dict:
    """summary(cost document) -> {wall_s, cpu_s, simulate_cpu_s, analysis_cpu_s, orbits, rss_mb} over all stages.

    ``analysis_cpu_s`` is every stage but simulate; ``rss_mb`` the largest per-process peak of any stage.
    """
    t = totals(doc)
    sim = t.get("simulate", {})
    return {
        "wall_s": sum(v["wall_s"] for v in t.values()),
        "cpu_s": sum(v["cpu_s"] for v in t.values()),
        "simulate_cpu_s": sim.get("cpu_s", 0.0),
        "analysis_cpu_s": sum(v["cpu_s"] for k, v in t.items() if k != "simulate"),
        "orbits": sim.get("orbits", 0),
        "rss_mb": max((max(v["rss_self_mb"], v["rss_children_mb"]) for v in t.values()), default=0.0),
    }
