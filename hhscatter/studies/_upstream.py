"""Reading other studies' published outputs (numbers JSON, derived tables) for the studies that build on them.

Figs 5 and 6 combine results of Figs 1–4 (the conservative c-measure, the
κ0(E) fit, μ, the τ table and lifetimes). Which study plays which role is
declared once, in the reading study's ``[needs]`` table.  Their key names are parameters of the reading
study's ``study.toml`` (dotted paths into the other study's JSON), so a
renamed key is a one-line change there, and a missing file or key fails with
a message that names the study, the path and the keys that do exist.

Development fallback: while an upstream study is not available, a study may
use the paper's value *only* if the environment variable
``HHSCATTER_DEV_FALLBACK=1`` is set; every such value is recorded with the
source ``"paper fallback (DEVELOPMENT ONLY)"`` in the numbers JSON and the
figure is stamped.  The default (and every make target) fails instead.
"""

from __future__ import annotations

import math

from hhscatter.analysis.stats.measured import Measured
from hhscatter.errors import HHScatterError, StudyError
from hhscatter.studies.study import DEV_ENV, dev_fallback_enabled, load_study

__all__ = [
    "DEV_ENV",
    "DEV_SOURCE",
    "UpstreamError",
    "any_fallback",
    "dev_fallback_enabled",
    "lookup",
    "numbers",
    "published_table",
    "table",
    "value_or_fallback",
]

DEV_SOURCE = "paper fallback (DEVELOPMENT ONLY)"


class UpstreamError(StudyError, FileNotFoundError):
    """Another study's output is missing or lacks an expected key."""


def lookup(doc: dict, path: str, *, what: str = "numbers JSON"):
    """lookup(doc, "a.b.c") -> (value, err) from a numbers JSON.

    Path components are separated by dots; a key that itself contains dots
    (e.g. "energies.E0.30.t_rec") is matched greedily (longest key first).

    A leaf ``{"value": v, "err": e}`` gives (v, e); a plain number (v, nan);
    anything else (lists, strings, dicts without "value") is returned as
    (leaf, nan).  A missing key raises UpstreamError listing the keys present
    at the level where the lookup failed.
    """
    cur = doc
    done = []
    parts = path.split(".")
    i = 0
    while i < len(parts):
        # keys may themselves contain dots ("E0.30"): take the longest match
        for j in range(len(parts), i, -1):
            part = ".".join(parts[i:j])
            if isinstance(cur, dict) and part in cur:
                cur = cur[part]
                break
            if (
                j == i + 1
                and isinstance(cur, list)
                and part.lstrip("-").isdigit()
                and -len(cur) <= int(part) < len(cur)
            ):
                cur = cur[int(part)]
                break
        else:
            have = sorted(cur)[:40] if isinstance(cur, dict) else type(cur).__name__
            where = ".".join(done) or "<top>"
            raise UpstreamError(f"{what}: no key {parts[i]!r} under {where} (path {path!r}); present: {have}")
        done.append(part)
        i = j
    if isinstance(cur, dict) and "value" in cur:
        err = cur.get("err")
        return cur["value"], (math.nan if err is None else err)
    if isinstance(cur, (int, float)) and not isinstance(cur, bool):
        return float(cur), math.nan
    return cur, math.nan


def numbers(study, other: str) -> dict:
    """numbers(study, other) -> the numbers JSON of study ``other`` at ``study``'s scale, or UpstreamError."""
    try:
        return study.read_numbers(other)
    except (FileNotFoundError, HHScatterError) as exc:
        raise UpstreamError(f"{study.name} needs the outputs of study {other!r}: {exc}") from None


def published_table(study, other: str, key: str, doc: dict | None = None):
    """published_table(study, other, key, doc=None) -> (DataFrame, file name): the derived table that study
    ``other`` publishes under ``"tables": {key: name}`` in its numbers JSON (``doc``, read if not given)."""
    doc = numbers(study, other) if doc is None else doc
    name = doc.get("tables", {}).get(key)
    if not name:
        raise UpstreamError(f"{other}.json names no published table {key!r} ('tables': {{'{key}': …}})")
    return table(study, other, name), name


def table(study, other: str, name: str, filters=None, columns=None):
    """table(study, other, name, filters=None, columns=None) -> pandas.DataFrame of study ``other``'s derived table.

    ``name`` is a file of ``studies/<other>/out/<scale>/derived/`` (same scale);
    ``filters`` and ``columns`` as for :func:`pandas.read_parquet` (read only what is needed: some
    published tables have 6e7 rows at paper scale). A study reads other studies'
    published outputs (numbers JSON, derived tables), never their raw runs.
    """
    import pandas as pd  # deferred: pandas loads on first use

    try:
        o = load_study(other, study.scale, root=study.root.parent)
    except StudyError as exc:
        raise UpstreamError(f"{study.name} needs study {other!r}: {exc}") from None
    path = o.out / "derived" / name
    if not path.exists():
        have = sorted(p.name for p in path.parent.glob("*")) if path.parent.is_dir() else []
        raise UpstreamError(
            f"{study.name} needs {path}, a derived table of study {other!r} (present: {have}); "
            f"run `make {study.name} SCALE={study.scale}`, which builds {other} first"
        )
    return pd.read_parquet(path, filters=filters, columns=columns)


def value_or_fallback(study, other: str, path: str, paper_value, inputs: dict, name: str):
    """value_or_fallback(study, other, path, paper_value, inputs, name) -> (value, err).

    The value at ``path`` in study ``other``'s numbers JSON; records
    ``inputs[name] = {value, err, source}``.  If that fails and the
    development fallback is enabled, the paper's value is used and labelled;
    otherwise the UpstreamError propagates.
    """
    try:
        v, e = lookup(numbers(study, other), path, what=f"{other}.json")
        inputs[name] = {**Measured(v, e).to_dict(), "source": f"{other}.json:{path}"}
        return v, e
    except UpstreamError as exc:
        if not dev_fallback_enabled():
            raise
        print(f"  WARNING {study.name}: {exc}\n  using the paper's {name} = {paper_value} ({DEV_SOURCE})", flush=True)
        inputs[name] = {**Measured(paper_value, math.nan).to_dict(), "source": DEV_SOURCE}
        return paper_value, math.nan


def any_fallback(inputs: dict) -> bool:
    """any_fallback(inputs) -> True if any recorded input is a development fallback."""
    return any(isinstance(v, dict) and v.get("source") == DEV_SOURCE for v in inputs.values())
