"""Where a study's published numbers come from, recorded in its numbers JSON and verified wherever they are read.

The analyze stage writes, beside the numbers (:meth:`hhscatter.studies.study.Study.write_numbers`)::

    "made_from": {"config_sha256": …,          # the study's configuration at its scale (study.toml, convention applied)
                  "upstream": {"fig3": …},     # the content hash of each upstream study's numbers JSON it read
                  "raw_runs": {"<key>": …}},   # the scene hash of each raw run (identical tables for one hash)
    "sha256": …                                # the content hash of the document itself (every key but this one)

A content hash is the sha256 of the document's canonical JSON (keys sorted, no spaces, every key but ``sha256``):
it does not change when the file is re-indented, and it changes with any value. :func:`verify_numbers` checks a
numbers JSON before it is used -- by the plot stage, by an analyze stage that reads it as an upstream, and by the
reproduction report -- and raises :class:`ProvenanceError` (exit status 2) naming the file when

* its content differs from its own hash (edited after analyze wrote it, or written by hand),
* the study's configuration at that scale is no longer the one it was made from (study.toml changed),
* an upstream numbers JSON is no longer the one it was made from, or
* the raw runs on this machine (``raw/done.json``) are not the ones it was made from.

Raw runs are checked where they are (a study's own out/ folder); the committed copies of the results in
docs/studies/assets/ have none, and are checked for everything else.

Examples
--------
>>> from hhscatter.analysis.stats import Measured
>>> config = {"study": {"fit_window": [0.0, 200.0]}}
>>> doc = sealed({"mu": Measured(0.9287, 0.001).to_dict(), "config": config,
...               "made_from": {"config_sha256": config_sha256(config), "upstream": {}, "raw_runs": {}}})
>>> verify_numbers(Path("fig3.json"), doc, config=config, scale="quick", upstream={})   # as written: passes
>>> doc["mu"]["value"] = 0.91                                                            # edited by hand
>>> verify_numbers(Path("fig3.json"), doc, config=config, scale="quick", upstream={})
Traceback (most recent call last):
...
hhscatter.studies.provenance.ProvenanceError: fig3.json was edited after it was written: its content hash is ...
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from hhscatter.errors import StudyError
from hhscatter.studies.jsonio import _jsonable

__all__ = ["ProvenanceError", "config_sha256", "content_sha256", "made_from", "sealed", "verify_numbers"]

SELF_KEY = "sha256"
MADE_FROM = "made_from"


class ProvenanceError(StudyError):
    """A numbers JSON was edited after it was written, or is stale: made from another study.toml, another upstream
    JSON or other raw runs than those there now."""


def _canonical(obj) -> bytes:
    return json.dumps(
        _jsonable(obj), sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False
    ).encode()


def content_sha256(doc: dict) -> str:
    """content_sha256(doc) -> sha256 hex digest of the canonical JSON of ``doc`` without its ``sha256`` key."""
    return hashlib.sha256(_canonical({k: v for k, v in doc.items() if k != SELF_KEY})).hexdigest()


def config_sha256(config: dict) -> str:
    """config_sha256(config) -> sha256 hex digest of a study's configuration (``Study.config``) as canonical JSON."""
    return hashlib.sha256(_canonical(config)).hexdigest()


def made_from(study, upstream_docs: dict) -> dict:
    """made_from(study, {name: numbers JSON}) -> the ``made_from`` record of a numbers JSON being written."""
    return {
        "config_sha256": config_sha256(study.config),
        "upstream": {name: content_sha256(doc) for name, doc in sorted(upstream_docs.items())},
        "raw_runs": {k: r.get("scene_hash") for k, r in sorted(study.raw_runs.items())},
    }


def sealed(doc: dict) -> dict:
    """sealed(doc) -> ``doc`` with its content hash under ``sha256`` (the last key)."""
    out = {k: v for k, v in doc.items() if k != SELF_KEY}
    out[SELF_KEY] = content_sha256(out)
    return out


def verify_numbers(
    path: Path, doc: dict, *, config: dict, scale: str, upstream: dict, raw: Path | None = None, remake: str = ""
) -> None:
    """verify_numbers(path, doc, *, config, scale, upstream, raw=None, remake='') -> None, or ProvenanceError.

    ``doc`` is the numbers JSON read from ``path``; ``config`` the study's configuration now (``Study.config``);
    ``upstream`` maps each upstream study the study needs to ``(path, doc)`` of its numbers JSON now (None where
    it is missing); ``raw`` the study's ``raw/`` folder (checked if it holds ``done.json``); ``remake`` the
    command that makes the file again, for the messages.
    """
    again = f"; {remake}" if remake else ""
    if doc.get(SELF_KEY) is None or not isinstance(doc.get(MADE_FROM), dict):
        raise ProvenanceError(
            f"{path} carries no record of what it was made from (no '{SELF_KEY}'/'{MADE_FROM}': "
            f"written before such records, or by hand){again}"
        )
    have = content_sha256(doc)
    if have != doc[SELF_KEY]:
        raise ProvenanceError(
            f"{path} was edited after it was written: its content hash is {have[:12]}…, the hash "
            f"it was written with {str(doc[SELF_KEY])[:12]}…{again}"
        )
    rec = doc[MADE_FROM]
    if rec.get("config_sha256") != config_sha256(config):
        raise ProvenanceError(
            f"{path} is stale: the study's configuration at scale {scale} (its study.toml, with "
            f"its convention) changed since these numbers were made{again}"
        )
    for name, (upath, udoc) in sorted(upstream.items()):
        want = (rec.get("upstream") or {}).get(name)
        if want is None:
            raise ProvenanceError(f"{path} records no hash of the numbers of study {name!r} it needs{again}")
        if udoc is None:
            raise ProvenanceError(
                f"{path} was made from the numbers of study {name!r}, which are missing here ({upath}){again}"
            )
        if content_sha256(udoc) != want:
            raise ProvenanceError(
                f"{path} is stale: it was made from another {upath.name} than {upath} (content "
                f"hash {content_sha256(udoc)[:12]}…, made from {want[:12]}…){again}"
            )
    done = Path(raw) / "done.json" if raw is not None else None
    if done is not None and done.exists():
        runs = {k: r.get("scene_hash") for k, r in (json.loads(done.read_text()).get("runs") or {}).items()}
        made = rec.get("raw_runs") or {}
        changed = sorted(k for k in made if runs.get(k) != made[k])
        if changed:
            raise ProvenanceError(
                f"{path} is stale: raw run {raw / changed[0]} now holds another scene than the one "
                f"these numbers were made from ({len(changed)} run(s) changed){again}"
            )
