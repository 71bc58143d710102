"""The committed results form one consistent build: every study's numbers JSON, at every published scale, was made
from the numbers JSON of each study it needs exactly as committed beside it (its ``made_from.upstream`` hash equals
the upstream file's content hash), and each file's own content hash holds. A study re-analysed without re-making
the studies that read it fails here, before a fresh ``make docs`` or ``make report`` would find it stale."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from hhscatter.studies import load_study
from hhscatter.studies.graph import studies
from hhscatter.studies.jsonio import _jsonable
from hhscatter.studies.provenance import config_sha256, content_sha256

ROOT = Path(__file__).resolve().parents[2]
ASSETS = {"quick": ROOT / "docs" / "studies" / "assets", "paper": ROOT / "docs" / "studies" / "assets" / "paper"}
NEEDS = {s.name: s.upstream for s in studies(ROOT / "studies")}


def _numbers(scale: str) -> dict:
    return {
        p.stem: json.loads(p.read_text())
        for p in sorted(ASSETS[scale].glob("*.json"))
        if not p.name.endswith(".cost.json") and p.stem in NEEDS
    }


def _stale(docs: dict) -> list:
    """The (study, upstream) pairs whose recorded upstream hash is not the committed upstream file's content hash."""
    stale = []
    for name, doc in docs.items():
        recorded = (doc.get("made_from") or {}).get("upstream") or {}
        for up in NEEDS[name]:
            if up not in docs:
                continue  # a study not published at this scale: nothing committed to compare with
            have = content_sha256(docs[up])
            if recorded.get(up) != have:
                stale.append(f"{name} <- {up}: made from {str(recorded.get(up))[:12]}…, committed {have[:12]}…")
    return stale


@pytest.mark.parametrize("scale", sorted(ASSETS))
def test_each_committed_study_was_made_from_the_committed_upstream_numbers(scale):
    docs = _numbers(scale)
    assert docs, f"no committed numbers at scale {scale}"
    stale = _stale(docs)
    assert not stale, f"scale {scale}: studies made from other upstream numbers than the committed ones: {stale}"


@pytest.mark.parametrize("scale", sorted(ASSETS))
def test_each_committed_numbers_file_carries_its_own_content_hash(scale):
    bad = [n for n, d in _numbers(scale).items() if d.get("sha256") != content_sha256(d)]
    assert not bad, f"scale {scale}: numbers edited after they were written: {bad}"


@pytest.mark.parametrize("scale", sorted(ASSETS))
def test_each_committed_study_was_made_from_its_configuration_now(scale):
    """A study.toml changed (a key added, a value moved) after its committed numbers were made: they are stale."""
    stale = [
        name
        for name, doc in _numbers(scale).items()
        if (doc.get("made_from") or {}).get("config_sha256") != config_sha256(_jsonable(load_study(name, scale).config))
    ]
    assert not stale, f"scale {scale}: numbers made from another configuration than study.toml's now: {stale}"


def test_the_check_finds_a_study_made_from_other_numbers():
    docs = _numbers("paper")
    name = next(n for n in docs if NEEDS[n] and all(u in docs for u in NEEDS[n]))
    up = NEEDS[name][0]
    assert f"{name} <- {up}" not in " ".join(_stale(docs))
    docs[up] = {**docs[up], "note": "re-analysed"}
    assert any(s.startswith(f"{name} <- {up}:") for s in _stale(docs))
