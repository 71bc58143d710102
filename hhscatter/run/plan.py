"""What a run plans and reports: chunks, tables, grid points, part-file paths, the manifest, the summary."""

from __future__ import annotations

from dataclasses import dataclass, field

from hhscatter.data.schema import part_name
from hhscatter.scene.grid import Grid
from hhscatter.scene.scene import Scene

SCENE_FILE = "scene.json"


@dataclass
class RunSummary:
    """Counts per outcome and timings of a run (or of one chunk)."""

    n: int = 0
    escaped: int = 0
    settled: int = 0
    censored: int = 0
    stopped: int = 0
    n_sections: int = 0
    n_snapshots: int = 0
    compute_seconds: float = 0.0  # time spent in chunks, summed over workers
    wall_seconds: float = 0.0
    chunks_done: int = 0
    chunks_skipped: int = 0
    workers: int = 1
    backend: str = "local"
    #: heyoka's event-detection failures (an event ignored in a step), per chunk that had any:
    #: {'<partition>/<chunk>' ('<chunk>' for a single scene): {"failures": n, "orbits_redone": m}}; every orbit
    #: they hit was redone on the reference driver
    event_failures: dict = field(default_factory=dict)
    #: orbits whose log-stretch Λ passed MAX_LOG_STRETCH (the tangent dynamics): in the chunks run now and, on a
    #: resume, in those kept (from their parts' metadata)
    tangent_beyond: int = 0

    def add(self, other: RunSummary):
        for k in (
            "n",
            "escaped",
            "settled",
            "censored",
            "stopped",
            "n_sections",
            "n_snapshots",
            "compute_seconds",
            "tangent_beyond",
        ):
            setattr(self, k, getattr(self, k) + getattr(other, k))
        self.event_failures.update(other.event_failures)
        self.chunks_done += 1

    def event_failures_record(self) -> dict:
        """The ``event_failures`` entry of the run's scene.json: total, orbits redone, counts per chunk."""
        chunks = self.event_failures
        return {
            "total": sum(c["failures"] for c in chunks.values()),
            "orbits_redone": sum(c["orbits_redone"] for c in chunks.values()),
            "chunks": dict(sorted(chunks.items())),
        }

    def line(self) -> str:
        if self.n == 0 and self.chunks_skipped:
            return f"nothing to do: all {self.chunks_skipped} chunk(s) verified complete and kept"
        us = 1e6 * self.wall_seconds / max(self.n, 1)
        us_core = 1e6 * self.compute_seconds / max(self.n, 1)
        skipped = f", {self.chunks_skipped} chunk(s) resumed" if self.chunks_skipped else ""
        where = "" if self.backend == "local" else f" on {self.backend}"
        return (
            f"{self.n} orbits: escaped {self.escaped}, settled {self.settled}, censored {self.censored}"
            f"{f', stopped {self.stopped}' if self.stopped else ''}"
            f" | wall {self.wall_seconds:.2f} s ({us:.2f} µs per orbit; {us_core:.2f} µs per orbit in the workers' chunks)"
            f" ({self.workers} worker{'s' if self.workers != 1 else ''}{where}{skipped})"
            + (
                f"\nheyoka event-detection failures: {self.event_failures_record()['total']} in "
                f"{len(self.event_failures)} chunk(s); {self.event_failures_record()['orbits_redone']} orbit(s) redone "
                "on the long-double reference driver (scene.json: event_failures)"
                if self.event_failures
                else ""
            )
            + (
                f"\n{self.tangent_beyond} orbit(s) with a log-stretch Λ above the tangent dynamics' 600: not "
                "guaranteed to be the orbits of the scene without them (scene.json: tangent_beyond)"
                if self.tangent_beyond
                else ""
            )
        )


def plan_chunks(scene: Scene):
    """plan_chunks(scene) -> iterator of (chunk, start, stop) covering orbits 0..n−1 (made lazily: no list
    of one tuple per chunk is held)."""
    c, n = scene.chunk_size, scene.n
    return ((i, s, min(s + c, n)) for i, s in enumerate(range(0, n, c)))


def tables_of(scene: Scene):
    names = ["lifetimes"]
    if scene.sections is not None:
        names.append("sections")
    if scene.snapshots:
        names.append("snapshots")
    if scene.follow is not None:
        names.append("crossings")
    return names


def points_of(run):
    """points_of(run) -> [(scene, partition)]: ('', the scene) for a Scene, one per grid point for a Grid."""
    if isinstance(run, Grid):
        return [(p, Grid.partition(p)) for p in run.points]
    return [(run, "")]


def part_rel(name: str, partition: str, chunk: int) -> str:
    """Relative path of a part file: '<table>/[<partition>/]part-<chunk>.parquet'."""
    return "/".join(x for x in (name, partition, part_name(chunk)) if x)


def _decode(d):
    """Undo the JSON encoding of infinities in a scene dict."""
    sec = d.get("sections")
    if sec:
        d["sections"] = {k: (float(v) if isinstance(v, str) else v) for k, v in sec.items()}
    return d


def manifest_of(points, tables) -> dict:
    """manifest_of([(scene, partition, scene_hash)], tables) -> the run's plan, as stored in scene.json.

    ``{"tables": [...], "points": [{"partition", "scene_hash", "n", "chunk_size"}]}``: the part files a
    complete run has are exactly part_rel(table, partition, chunk) for chunk < ceil(n/chunk_size), each
    carrying ``scene_hash`` and its orbit range in its metadata (:func:`hhscatter.data.read.run_parts`).
    """
    return {
        "tables": list(tables),
        "points": [
            {"partition": part, "scene_hash": h, "n": int(sc.n), "chunk_size": int(sc.chunk_size)}
            for sc, part, h in points
        ],
    }
