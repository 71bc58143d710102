"""Record, in committed study results made before numbers carried their provenance, what can still be checked.

    python tools/stamp_assets.py [--scale paper] [--check]

The numbers JSON in docs/studies/assets/ (quick) and docs/studies/assets/<scale>/ were copied there from studies
run elsewhere; their raw runs are not in the repository. The analyze stage now writes a ``made_from`` record and
a content hash into every numbers JSON (:mod:`hhscatter.studies.provenance`), which the report verifies. For a
committed copy without them, this tool writes them only after checking what the repository still allows:

* its ``config`` (the study.toml it was made from, at its scale) equals the study's configuration now, else it
  is stale and is not stamped;
* every value it records as read from an upstream study's numbers (an ``inputs`` leaf whose ``source`` is
  ``<upstream>.json:<key>``) equals that value in the committed copy of the upstream's numbers, to 1 % of its
  error (or 1e-9 relative without one), else it is not stamped;
* the upstream hashes it records are those of the upstream copies as stamped (studies in graph order).

What cannot be checked is said in the record (``made_from.stamped``): the raw runs (not here), values read from
an upstream's derived tables (not committed), and the content itself before stamping (its history is the
repository's). From then on the report refuses a copy edited by hand or made stale. ``--check`` writes nothing
and exits 1 if a copy lacks a valid record.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hhscatter.studies import load_study, study_names  # noqa: E402
from hhscatter.studies._upstream import lookup  # noqa: E402
from hhscatter.studies.jsonio import _jsonable  # noqa: E402
from hhscatter.studies.provenance import config_sha256, content_sha256, sealed  # noqa: E402

TOL_ERR = 0.01  # a value read from an upstream agrees with the upstream's if |Δ| ≤ 1 % of its error
TOL_REL = 1e-9  # ... or, without an error, to this relative tolerance


def assets_dir(scale: str) -> Path:
    base = ROOT / "docs" / "studies" / "assets"
    return base if scale == "quick" else base / scale


def _sources(doc, upstream: str):
    """(key path in the upstream JSON, value, err) of every leaf of ``doc`` that says it was read from it."""
    out = []

    def walk(x):
        if isinstance(x, dict):
            src = x.get("source")
            if isinstance(src, str) and src.startswith(f"{upstream}.json") and "value" in x:
                key = src[len(upstream) + 5 :].lstrip(": ").strip()
                out.append((key, x.get("value"), x.get("err")))
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)

    walk(doc)
    return out


def _diff(a, b, err) -> float:
    """Largest |a − b| in units of the tolerance (≤ 1 agrees); inf where the structures differ."""
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return max([_diff(x, y, err) for x, y in zip(a, b)] or [0.0]) if len(a) == len(b) else math.inf
    if isinstance(a, dict) and isinstance(b, dict):
        return max([_diff(a[k], b[k], err) for k in a] or [0.0]) if a.keys() == b.keys() else math.inf
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        tol = (
            TOL_ERR * err
            if isinstance(err, (int, float)) and err and math.isfinite(err)
            else TOL_REL * max(1.0, abs(a), abs(b))
        )
        return abs(a - b) / tol if tol else (0.0 if a == b else math.inf)
    return 0.0 if a == b else math.inf


def stamp(name: str, scale: str, stamped: dict) -> tuple[dict | None, str]:
    """stamp(name, scale, {upstream name: its stamped doc}) -> (stamped doc or None, what was checked / why not)."""
    path = assets_dir(scale) / f"{name}.json"
    doc = json.loads(path.read_text())
    study = load_study(name, scale)
    if doc.get("config") != _jsonable(study.config):
        return None, f"{path.relative_to(ROOT)}: its config is not the study's configuration now (stale): not stamped"
    checks, upstream = [], {}
    for other in sorted(set(study.needs.values())):
        udoc = stamped.get(other)
        if udoc is None:
            return None, f"{path.relative_to(ROOT)}: the committed numbers of {other} are not stamped: not stamped"
        found = _sources(doc, other)
        for key, value, err in found:
            theirs, _ = lookup(udoc, key, what=f"{other}.json")
            d = _diff(value, theirs, err)
            if d > 1:
                return None, (
                    f"{path.relative_to(ROOT)}: its {other}.json:{key} = {value!r} is not the committed "
                    f"{other}.json's {theirs!r}: stale, not stamped"
                )
            checks.append(f"{other}.json:{key} equal to the committed {other}.json ({d:.2g} of the tolerance)")
        if not found:
            checks.append(
                f"no value recorded as read from {other}.json: only its derived tables (not committed), not checked"
            )
        upstream[other] = content_sha256(udoc)
    doc["made_from"] = {
        "config_sha256": config_sha256(study.config),
        "upstream": upstream,
        "raw_runs": {k: r.get("scene_hash") for k, r in sorted((doc.get("raw_runs") or {}).items())},
        "stamped": {
            "note": "recorded after the fact from the committed copy (tools/stamp_assets.py): its config "
            "equals study.toml at this scale (checked); its raw runs are not in the repository "
            "(not checked); its content before this record is as committed",
            "checks": checks,
        },
    }
    return sealed(doc), "; ".join(checks) or "no upstream"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", action="append", help="scale(s) to stamp (default: quick and paper)")
    ap.add_argument("--check", action="store_true", help="write nothing; exit 1 if a copy lacks a valid record")
    a = ap.parse_args(argv)
    bad = 0
    for scale in a.scale or ["quick", "paper"]:
        done = {}
        for name in study_names():
            path = assets_dir(scale) / f"{name}.json"
            if not path.exists():
                continue
            current = json.loads(path.read_text())
            if a.check:
                try:
                    load_study(name, scale).verify_numbers(
                        path, current, pick=lambda o, s=scale: assets_dir(s) / f"{o}.json", raw=False
                    )
                except Exception as exc:  # noqa: BLE001 - reported, counted
                    print(f"{scale}/{name}: {exc}")
                    bad += 1
                continue
            doc, what = stamp(name, scale, done)
            if doc is None:
                print(what)
                bad += 1
                continue
            done[name] = doc
            path.write_text(json.dumps(_jsonable(doc), indent=2, sort_keys=False, allow_nan=False) + "\n")
            print(f"stamped {path.relative_to(ROOT)}: {what}")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
