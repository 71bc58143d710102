"""Result numbers in prose, rendered from the committed study JSON: one source of truth for every number.

A page (a study's ``page.md``, a docs page, the README's generated table)
never types a result by hand. It names it, and the number is read from the
study's committed numbers JSON when the page is built::

    c = [[fig2:kappa_fit.c]]                          → c = 1.435 ± 0.017  (headline scale)
    quick scale: [[fig2@quick:kappa_fit.c]]           → the quick-scale JSON
    [[fig2:kappa_fit.c|value]], [[fig2:kappa_fit.c|err]]
    [[fig2:kappa_energy[energy=0.27].kappa|.4f]]      → a record of a list, chosen by a field
    [[fig5:paper_comparison[quantity=d_rel].verdict]] → a row's verdict, by the one rule
    [[reading:fig5.premise]]                         → a generated reading (hhscatter.publish.readings)

The reference is ``[[study[@scale]:path[|format]]]``:

* ``study`` — the study folder's name; ``scale`` — ``paper`` or ``quick``;
  without it the **headline scale**: ``paper`` where the study's paper-scale
  JSON is committed (``docs/studies/assets/paper/<study>.json``), else
  ``quick`` (``docs/studies/assets/<study>.json``). See :func:`headline_scale`.
* ``path`` — keys separated by dots (a key that itself holds dots, such as
  ``E0.30``, is found as it is); ``[n]`` indexes a list, ``[field=value]``
  (or ``[f=a,g=b]``) picks the one record of a list whose fields equal
  these values (numbers compared as numbers).
* ``format`` (see :func:`format_leaf`) — none: ``value ± err`` with the
  error's significant digits (:func:`hhscatter.publish.formatting.format_value_err`);
  ``value`` / ``err``: one of them at those digits; ``ci`` / ``ci+``: value
  [lo, hi] of an interval (a ``{value, interval}`` leaf, or a number beside
  its ``<key>_interval``), decimals from its half-width, ``+``: signed;
  ``pm``: a number ± its sibling ``<key>_err``; ``pct``: ×100 with ``%``; ``verdict``: the verdict of a paper-vs-ours row by
  the one rule (:func:`hhscatter.reproduction.verdicts.row_verdict`);
  ``abs``: the magnitude; ``int``: rounded, thousands separated by a thin
  space; ``sci``: a×10ᵇ; a Python format spec (``.3f``, ``.2g``, ``+.2f``).

A reference that does not resolve is an error (:class:`NumberRefError`): the
docs build fails, it never prints a stale or a made-up number. The syntax is
chosen not to collide with TeX (``{{`` and ``{#`` are TeX and attribute-list
syntax on these pages), so a reference may stand inside ``$…$`` maths too.

:func:`stray_numbers` is the other half: it lists the numbers a page's prose
types by hand that are neither references nor declared conventions
(``<!-- conventions: … -->``); the docs tests fail on any. :func:`typed_readings` does the same for readings (agrees, within a factor, holds,
never, …), which a page names as ``[[reading:name]]`` (:mod:`hhscatter.publish.readings`).
"""

from __future__ import annotations

import copy
import json
import math
import re
import tomllib
from functools import lru_cache
from pathlib import Path

from hhscatter.analysis.stats.intervals import fraction_with_bound
from hhscatter.analysis.stats.measured import Measured
from hhscatter.publish.formatting import format_bound, format_number, format_value_err, leaf_bound, typographic_minus
from hhscatter.publish.words import in_glossary_words
from hhscatter.studies.provenance import SELF_KEY, content_sha256

__all__ = [
    "NumberRefError",
    "REF",
    "format_leaf",
    "format_ref",
    "headline_scale",
    "prose",
    "read_numbers_file",
    "render_refs",
    "resolve",
    "stray_numbers",
    "typed_readings",
]

#: ``[[study[@scale]:path[|format]]]``; ``]]`` closes it (a ``[…]`` selector inside the path is fine); the bar may
#: be written ``\|`` where the source is a Markdown table that other tools read as it is
REF = re.compile(
    r"\[\[\s*(?P<study>[\w-]+)(?:@(?P<scale>[\w-]+))?\s*:\s*(?P<path>(?:[^\]\[|\\]|\[[^\]]*\])+?)"
    r"\s*(?:\\?\|\s*(?P<fmt>[^\]]+?)\s*)?\]\]"
)


class NumberRefError(ValueError):
    """A ``[[study:path]]`` reference that the committed JSON does not hold (or a bad format)."""


def assets_dir(root: Path, scale: str) -> Path:
    """The committed study outputs at ``scale`` under repository ``root`` (``docs/studies/assets[/<scale>]``)."""
    base = Path(root) / "docs" / "studies" / "assets"
    return base if scale == "quick" else base / scale


def headline_scale(root: Path, study: str) -> str:
    """headline_scale(repository root, study) -> "paper" when its paper-scale JSON is committed, else "quick".

    The one scale every page, the index and the README headline; the other
    scale is named explicitly (``[[fig2@quick:…]]``).
    """
    return "paper" if (assets_dir(root, "paper") / f"{study}.json").is_file() else "quick"


def _load(path: str) -> dict:
    """The numbers JSON at ``path``, refused when its content is not the one it was written with (its ``sha256``).

    Parsed once per content (the cache is keyed by the file's bytes, so a file rewritten within the clock's
    resolution is read again). Rows written before they carried their count get it from the record itself
    (:func:`hhscatter.reproduction.escape_criterion.with_return_counts`): a count of 0 reads as its bound; rows of
    κ from the c-measure written before they carried their reference get it from the record
    (:func:`hhscatter.reproduction.fig2.with_cmeasure_references`); text
    written before the studies used the glossary's words is read in them (:func:`hhscatter.publish.words.in_glossary_words`)."""
    return _parse(path, Path(path).read_bytes())


@lru_cache(maxsize=64)
def _parse(path: str, raw: bytes) -> dict:
    doc = json.loads(raw)
    if doc.get(SELF_KEY) is None or content_sha256(doc) != doc[SELF_KEY]:
        raise NumberRefError(
            f"{path} is not as its study wrote it (no content hash, or another content than the hash it was written "
            "with): a page quotes no number from an edited file; make the study again and copy its results"
        )
    from hhscatter.reproduction.escape_criterion import with_return_counts  # deferred: pandas loads on first use
    from hhscatter.reproduction.fig2 import with_cmeasure_references  # deferred: pandas loads on first use

    return in_glossary_words(with_cmeasure_references(with_return_counts(doc)))


def read_numbers_file(path: Path) -> dict:
    """read_numbers_file(path) -> a committed numbers JSON, verified against its content hash.

    Every reader that puts a study's numbers on a page goes through here (the ``[[study:path]]`` references
    and the docs hooks' generated tables alike); raises :class:`NumberRefError` for an edited or unsealed file.
    """
    return copy.deepcopy(_load(str(path)))


def load_numbers(root: Path, study: str, scale: str | None = None) -> tuple[dict, str]:
    """(numbers JSON, scale) of a study's committed outputs; ``scale=None``: the headline scale."""
    scale = scale or headline_scale(root, study)
    path = assets_dir(root, scale) / f"{study}.json"
    if not path.is_file():
        raise NumberRefError(
            f"no committed numbers for study {study!r} at scale {scale!r} ({path.name} "
            f"missing from docs/studies/assets{'' if scale == 'quick' else '/' + scale})"
        )
    return _load(str(path)), scale


_SEG = re.compile(r"\[([^\]]*)\]")


def _split(path: str) -> list[str]:
    """'a.b[k=v].c[0]' -> ['a', 'b', '[k=v]', 'c', '[0]'] (dots inside [...] kept)."""
    out, buf, depth = [], "", 0
    for ch in path:
        if ch == "[" and depth == 0:
            if buf:
                out.append(buf)
            buf, depth = "[", 1
        elif ch == "]" and depth == 1:
            out.append(buf + "]")
            buf, depth = "", 0
        elif ch == "." and depth == 0:
            if buf:
                out.append(buf)
            buf = ""
        else:
            buf += ch
    if buf:
        out.append(buf)
    return out


def _same(a, b: str) -> bool:
    if isinstance(a, (int, float)) and not isinstance(a, bool):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-12, abs_tol=1e-15)
        except ValueError:
            return False
    return str(a) == b


def resolve(doc, path: str):
    """resolve(numbers JSON, 'kappa_fit.c') -> the leaf at ``path`` (see the module doc); NumberRefError if absent.

    Examples
    --------
    >>> doc = {"fit": {"c": Measured(1.43, 0.02).to_dict()}, "E0.30": {"n": 7}, "rows": [{"E": 0.25, "k": 0.09}]}
    >>> resolve(doc, "fit.c"), resolve(doc, "E0.30.n"), resolve(doc, "rows[E=0.25].k")
    ({'value': 1.43, 'err': 0.02}, 7, 0.09)
    """
    parts = _split(path.strip())
    node, i, seen = doc, 0, []
    while i < len(parts):
        p = parts[i]
        if p.startswith("["):
            sel = p[1:-1].strip()
            if not isinstance(node, list):
                raise NumberRefError(f"{'.'.join(seen) or '(top)'} is not a list: cannot apply {p}")
            if re.fullmatch(r"-?\d+", sel):
                k = int(sel)
                if not -len(node) <= k < len(node):
                    raise NumberRefError(f"{'.'.join(seen)}{p}: index out of range ({len(node)} items)")
                node = node[k]
            else:
                fields = {k for r in node if isinstance(r, dict) for k in r}
                conds = []
                for c in re.split(r",(?=\s*[\w.-]+\s*=)", sel):
                    name = c.partition("=")[0].strip()
                    if conds and name not in fields:  # a comma inside a value ("κ(E=0.30, r_esc=1.5)")
                        f, eq, w = conds.pop()
                        conds.append((f, eq, w + "," + c))
                    else:
                        conds.append(c.partition("="))
                if not all(eq for _, eq, _ in conds):
                    raise NumberRefError(f"selector {p}: write [index], [field=value] or [field=value,field=value]")
                conds = [(f.strip(), w.strip()) for f, _, w in conds]
                hits = [r for r in node if isinstance(r, dict) and all(f in r and _same(r[f], w) for f, w in conds)]
                if len(hits) != 1:
                    raise NumberRefError(f"{'.'.join(seen)}{p}: {len(hits)} records match (need exactly one)")
                node = hits[0]
            seen.append(p)
            i += 1
            continue
        if not isinstance(node, dict):
            raise NumberRefError(f"{'.'.join(seen) or '(top)'} has no key {p!r} (it is not a mapping)")
        # a key may itself hold dots ('E0.30'): the longest run of parts that is a key wins
        for j in range(len(parts), i, -1):
            chunk = parts[i:j]
            if any(c.startswith("[") for c in chunk):
                continue
            key = ".".join(chunk)
            if key in node:
                node = node[key]
                seen.append(key)
                i = j
                break
        else:
            keys = ", ".join(list(node)[:12])
            raise NumberRefError(f"no key {p!r} under {'.'.join(seen) or '(top)'} (keys: {keys})")
    return node


_SUP = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _sci(v: float, sig: int = 3) -> str:
    m, e = f"{v:.{sig - 1}e}".split("e")
    return f"{m}×10{str(int(e)).translate(_SUP)}"


def _num(v: float) -> str:
    """A number alone, 4 significant digits, a×10ᵇ outside [1e-3, 1e5) (plain text: fine in prose and maths)."""
    if isinstance(v, float) and math.isfinite(v) and v != 0 and not 1e-3 <= abs(v) < 1e5:
        return _sci(v, 4)
    return format_number(v)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _digits(err: float) -> int:
    """Decimal places that show ``err`` to 1 significant digit (2 when it starts with 1 or 2)."""
    exp10 = int(math.floor(math.log10(err)))
    return max(0, -exp10 + (1 if err / 10.0**exp10 < 3 else 0))


def format_leaf(leaf, fmt: str | None = None) -> str:
    """format_leaf(JSON leaf, format) -> its text (see _format_leaf); a negative number with the minus sign "−"
    (:func:`hhscatter.publish.formatting.typographic_minus`, as the docs tables and the report write it)."""
    out = _format_leaf(leaf, fmt)
    value = leaf.value if isinstance(leaf, Measured) else leaf.get("value") if isinstance(leaf, dict) else None
    if isinstance(leaf, str) or isinstance(value, str):
        return out
    return typographic_minus(out)


def _measured(value, err) -> Measured:
    """A leaf's value with its error as :class:`~hhscatter.analysis.stats.measured.Measured`: an error that is no
    number (None, text) is NaN, not measured; the value is kept as it is (a number, or text to write as it is)."""
    return Measured(value, err if _is_num(err) else math.nan)


def _format_leaf(leaf, fmt: str | None = None) -> str:
    """format_leaf(JSON leaf, format) -> its text (see the module doc for the formats).

    A ``{value, err}`` leaf (or a :class:`~hhscatter.analysis.stats.measured.Measured`) is written
    ``value ± err`` with the error's significant digits, or ``value`` alone when its error is missing,
    None, NaN or 0; ``{value, lo, hi}`` as ``value [lo, hi]``; a number without error with 4 significant
    digits; text as it is. A missing value (None, NaN) is an error, never "nan".

    Examples
    --------
    >>> leaf = Measured(1.4348590, 0.0170464).to_dict()
    >>> format_leaf(leaf), format_leaf(leaf, "value"), format_leaf(leaf, "err"), format_leaf(0.0623, "pct")
    ('1.435 ± 0.017', '1.435', '0.017', '6.23 %')
    >>> format_leaf(Measured(0.0623, 0.0011), "pct"), format_leaf(Measured(0.0623), "pct")
    ('6.23 ± 0.11 %', '6.23 %')
    """
    fmt = (fmt or "").strip()
    value, err = leaf, None
    if isinstance(leaf, dict) and "value" not in leaf and "ours" in leaf:  # a paper-vs-ours row: our number
        leaf = _measured(leaf["ours"], leaf.get("err"))
    if isinstance(leaf, Measured):
        value, err = leaf.value, leaf.err
    elif isinstance(leaf, dict):
        if "value" not in leaf:
            raise NumberRefError(f"a mapping with keys {sorted(leaf)[:8]}: name one of them")
        value, err = leaf["value"], leaf.get("err")
        if fmt == "" and _is_num(leaf.get("lo")) and _is_num(leaf.get("hi")) and _is_num(value):
            return f"{_num(value)} [{_num(leaf['lo'])}, {_num(leaf['hi'])}]"
    if fmt.startswith("ci") or (isinstance(leaf, dict) and "interval" in leaf and fmt in ("", "+")):
        return _interval(leaf, fmt)
    if isinstance(value, str) and fmt in ("", "text"):
        return value
    if isinstance(value, bool):
        return "yes" if value else "no"
    if not _is_num(value) or (isinstance(value, float) and not math.isfinite(value)):
        raise NumberRefError(f"no number here (value {value!r})")
    has_err = _is_num(err) and math.isfinite(err) and err > 0
    if fmt == "abs":
        value, fmt = abs(value), ""
    if fmt == "pct":
        value, err, fmt = 100 * value, (100 * err if has_err else err), ""
        return _format_leaf(_measured(value, err)) + " %"
    if fmt == "":
        return format_value_err(value, err) if has_err else _num(value)
    if fmt in ("value", "err"):
        if not has_err:
            if fmt == "err":
                raise NumberRefError("no uncertainty recorded for this number")
            return _num(value)
        d = _digits(err)
        if abs(value) >= 1e4 or d > 5:
            return _sci(value) if fmt == "value" else _sci(err, 2)
        return f"{value if fmt == 'value' else err:.{d}f}"
    if fmt == "int":
        return f"{int(round(value)):,}".replace(",", "\u2009")
    if fmt == "sci":
        return _sci(float(value))
    try:
        return format(value, fmt)
    except (ValueError, TypeError) as e:
        raise NumberRefError(f"bad format {fmt!r}: {e}") from None


def _interval(leaf, fmt: str) -> str:
    """``value [lo, hi]`` of ``{value, interval: [lo, hi]}`` (or ``[value, [lo, hi]]``), decimals from the
    half-width of the interval as from an error; ``ci+`` / ``+``: signed."""
    if isinstance(leaf, dict):
        value, iv = leaf.get("value"), leaf.get("interval")
    elif isinstance(leaf, (list, tuple)) and len(leaf) == 2:
        value, iv = leaf
    else:
        raise NumberRefError(
            f"no interval here ({leaf!r:.60}): write path.to.x with a sibling x_interval, or a {{value, interval}} leaf"
        )
    nums = [value, *(iv or [])] if isinstance(iv, (list, tuple)) and len(iv) == 2 else None
    if nums is None or not all(_is_num(x) and math.isfinite(x) for x in nums):
        raise NumberRefError(f"no number or no interval here (value {value!r}, interval {iv!r})")
    half = (nums[2] - nums[1]) / 2
    d = _digits(half) if half > 0 else 3
    sign = "+" if "+" in fmt else ""
    lo, hi = nums[1], nums[2]
    return f"{value:{sign}.{d}f} [{lo:{sign}.{d}f}, {hi:{sign}.{d}f}]".replace("-", "−")


# -- pages ------------------------------------------------------------------------------------------------------
_FENCE = re.compile(r"^(?P<i>[ \t]*)(?P<f>```+|~~~+).*?^(?P=i)(?P=f)[ \t]*$", re.M | re.S)
_CODE = re.compile(r"(`+)(?!`).+?(?<!`)\1(?!`)", re.S)
_COMMENT = re.compile(r"<!--.*?-->", re.S)


def _protected(text: str) -> list[tuple[int, int]]:
    """Spans of ``text`` that are code (fences, inline code) or HTML comments: never rewritten, never scanned."""
    spans = [m.span() for m in _FENCE.finditer(text)] + [m.span() for m in _COMMENT.finditer(text)]

    def inside(i):
        return any(a <= i < b for a, b in spans)

    spans += [m.span() for m in _CODE.finditer(text) if not inside(m.start())]
    return sorted(spans)


def format_ref(doc, path: str, fmt: str | None = None) -> str:
    """The text of one reference: :func:`resolve` then :func:`format_leaf`; with ``ci`` a number whose interval
    is its sibling ``<key>_interval`` (``rows[…].delta`` beside ``rows[…].delta_interval``) is written with it."""
    scale = doc.get("scale") if isinstance(doc, dict) else None
    stripped = path.strip()
    if stripped.endswith(".verdict") and not fmt:  # a row's or a claim's verdict: by the one rule, not as stored
        parent = resolve(doc, stripped[: -len(".verdict")])
        if isinstance(parent, dict) and ("ours" in parent or "reference" in parent):
            return _rule_verdict(parent, scale)
    leaf = resolve(doc, path)
    bound = _bound_of(doc, stripped, leaf)
    f = (fmt or "").strip()
    if bound is not None and (f in ("", "pct", "value") or f.startswith(".")):
        # a count of 0 (or of all): its one-sided bound, never "0 ± 0"
        return typographic_minus(format_bound(**bound, pct=(fmt or "").strip() == "pct"))
    if (fmt or "").strip() == "verdict":  # a paper-vs-ours row: its verdict by the one rule
        if not isinstance(leaf, dict) or not ("ours" in leaf or "reference" in leaf):
            raise NumberRefError("the format 'verdict' needs a paper-vs-ours row (with 'ours') or a claim record")
        return _rule_verdict(leaf, scale)
    if (fmt or "").strip() == "pm" and _is_num(leaf):  # a number beside its error <key>_err
        return format_leaf(_measured(leaf, resolve(doc, path.strip() + "_err")))
    if (fmt or "").strip().startswith("ci") and _is_num(leaf):
        leaf = [leaf, resolve(doc, path.strip() + "_interval")]
    return format_leaf(leaf, fmt)


def _bound_of(doc, path: str, leaf) -> dict | None:
    """The one-sided bound of a number recorded at a count of 0 or of all: {upper | lower, cl} from its siblings
    ``<key>_upper`` / ``<key>_lower`` and ``<key>_cl`` (:meth:`hhscatter.analysis.stats.intervals.BoundedFraction.record`),
    or from a ``{value, upper, cl}`` or ``{value, lo, hi, n}`` leaf (:func:`hhscatter.publish.formatting.leaf_bound`);
    None when it has none.

    >>> _bound_of({"r": {"P": 0.0, "P_upper": 3e-4, "P_cl": 0.95}}, "r.P", 0.0)
    {'cl': 0.95, 'upper': 0.0003}
    """
    if isinstance(leaf, dict):
        return leaf_bound(leaf)
    if not _is_num(leaf):
        return None
    found = {}
    for k in ("upper", "lower", "cl"):
        try:
            v = resolve(doc, f"{path}_{k}")
        except NumberRefError:
            continue
        if _is_num(v):
            found[k] = v
    if ("upper" in found) == ("lower" in found):
        return _derived_bound(doc, path, leaf) if not found else None
    return {"cl": 0.95, **found}


def _derived_bound(doc, path: str, leaf) -> dict | None:
    """The 95 % one-sided bound of a fraction of 0 or 1 recorded without one (a record written before bounds were
    recorded): from the number of orbits ``n`` of its record, by the estimator that records them
    (:func:`hhscatter.analysis.stats.intervals.fraction_with_bound`); None for any other number.

    >>> b = _derived_bound({"rows": [{"id": "a", "fraction": 0.0, "n": 10000}]}, "rows[id=a].fraction", 0.0)
    >>> b["cl"], round(b["upper"], 7)  # 1 − 0.05^(1/10000)
    (0.95, 0.0002995)
    """
    parts = _split(path)
    name = parts[-1] if parts else ""
    if leaf not in (0, 1) or not (name == "fraction" or name.endswith("_fraction")) or len(parts) < 2:
        return None
    parent = "".join(p if p.startswith("[") or i == 0 else f".{p}" for i, p in enumerate(parts[:-1]))
    try:
        n = resolve(doc, parent).get("n")
    except (NumberRefError, AttributeError):
        return None
    if not isinstance(n, int) or isinstance(n, bool) or n <= 0:
        return None
    b = fraction_with_bound(round(leaf * n), n)
    bound = {"upper": b.upper} if b.upper is not None else {"lower": b.lower}
    return {"cl": b.cl, **bound}


def _rule_verdict(row: dict, scale) -> str:
    """The verdict of a paper-vs-ours row or a claim record by the one rule
    (:func:`hhscatter.reproduction.verdicts.row_verdict`, :func:`~hhscatter.reproduction.verdicts.claim_verdict`),
    its minus signs typographic."""
    from hhscatter.reproduction.verdicts import claim_verdict, row_verdict  # deferred: only verdicts need it

    return row_verdict(row, scale) if "ours" in row else claim_verdict(row, scale)


def _reading(root: Path, name: str) -> str:
    """The sentence of reading ``name`` (:func:`hhscatter.publish.readings.reading`) from the committed numbers under
    ``root``; NumberRefError when unknown or when the numbers it reads are missing."""
    from hhscatter.publish.readings import reading  # deferred: only pages with readings need it (numpy, scipy)

    try:
        return reading(lambda study, scale: load_numbers(root, study, scale)[0], name.strip())
    except (KeyError, StopIteration, TypeError, ValueError) as e:
        raise NumberRefError(f"reading {name!r}: {e}") from None


def render_refs(text: str, root: Path, *, where: str = "") -> str:
    """Every ``[[study:path]]`` of ``text`` (outside code) replaced by its number; NumberRefError names them all."""
    spans = _protected(text)
    errors = []

    def sub(m):
        if any(a <= m.start() < b for a, b in spans):
            return m.group(0)
        try:
            if m.group("study") == "reading":  # a generated reading (hhscatter.publish.readings)
                return _reading(root, m.group("path"))
            doc, _ = load_numbers(root, m.group("study"), m.group("scale"))
            return format_ref(doc, m.group("path"), m.group("fmt"))
        except NumberRefError as e:
            errors.append(f"{m.group(0)}: {e}")
            return m.group(0)

    out = REF.sub(sub, text)
    # what looks like a reference but did not parse (e.g. brackets inside a selector's value) is an error too
    spans = _protected(out)
    for m in re.finditer(r"\[\[\s*[\w-]+(?:@[\w-]+)?\s*:", out):
        if not any(a <= m.start() < b for a, b in spans):
            line = out[m.start() : out.find("\n", m.start())][:80]
            errors.append(
                f"{line}: not a reference the syntax reads ([[study[@scale]:path[|format]]]; a selector "
                "value may not hold brackets)"
            )
    if errors:
        raise NumberRefError(f"{where or 'text'}: " + "; ".join(errors))
    return out


# -- numbers typed by hand --------------------------------------------------------------------------------------
_CONVENTIONS = re.compile(r"<!--\s*conventions:(.*?)-->", re.S)
_NUMBER = re.compile(
    r"(?<![\w.\-/−])[-−+]?(?:\d+(?:[.,]\d+)?|\.\d+)(?:[eE][-+]?\d+)?(?:[⁰¹²³⁴⁵⁶⁷⁸⁹⁻]+)?"
    r"(?![\w.]*\w)"
)
#: references to the paper's and the site's own parts ("Fig. 2", "Eq. (3)", "Eqs. (14)–(16)", "Table 1",
#: "panel 2"), the paper's arXiv id and years (2023): numbers that name things, not results
_NAMING = re.compile(
    r"(?:\b(?:Figs?|Eqs?|Sec|Secs|Table|Tables|Ref|App)\.?\s*\(?\d+[a-z]?\)?"
    r"(?:\s*(?:[–,-]|and|to)\s*\(?\d+[a-z]?\)?)*|arXiv:\d+\.\d+|(?<![\d.])(?:19|20)\d\d(?![\d.,]\d|[²³])|\(\d+\)(?=\s*[,.;:)–]|\s*$))",
    re.M,
)
_LINK_TARGET = re.compile(r"\]\([^)]*\)|\]\[[^\]]*\]|\{[#.][^}]*\}|</?[a-zA-Z][^>]*>|\(eqn?:[\w-]+\)|fig:[\w-]+")
#: small integers name counts, panels and exponents ("4 windows", "(2)", "t^2"): never a measured result here
SMALL_INT = 12


def prose(text: str) -> str:
    """``text`` with everything that is not prose blanked (code, comments, references, link targets, tags,
    figure/equation names); offsets and line numbers kept."""
    chars = list(text)

    def blank(a, b):
        for i in range(a, b):
            if chars[i] != "\n":
                chars[i] = " "

    for a, b in _protected(text):
        blank(a, b)
    for rx in (REF, _LINK_TARGET, _NAMING):
        for m in rx.finditer("".join(chars)):
            blank(*m.span())
    return "".join(chars)


def _as_float(tok: str):
    t = tok.replace("−", "-").replace(",", ".")
    sup = re.search(r"[⁰¹²³⁴⁵⁶⁷⁸⁹⁻]+$", t)
    if sup:
        base, power = t[: sup.start()], sup.group(0).translate(str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻", "0123456789-"))
        # 10⁶ is a power of ten; 512² a grid of 512 × 512 (the number typed is 512)
        t = f"1e{power}" if base.endswith("10") and base.rstrip("×") in ("10", "1×10") else base
    try:
        return float(t)
    except ValueError:
        return None


def numbers_in(obj) -> set[float]:
    """Every number in a JSON/TOML-like value (dicts, lists, numbers, and numbers written inside strings)."""
    out: set[float] = set()
    if isinstance(obj, dict):
        for k, v in obj.items():
            out |= numbers_in(k) | numbers_in(v)
    elif isinstance(obj, (list, tuple)):
        for v in obj:
            out |= numbers_in(v)
    elif isinstance(obj, bool):
        pass
    elif isinstance(obj, (int, float)):
        out.add(float(obj))
    elif isinstance(obj, str):
        for m in re.finditer(r"\d+(?:\.\d+)?(?:[eE][-+]?\d+)?", obj):
            v = _as_float(m.group(0))
            if v is not None:
                out.add(v)
    return out


def declared_conventions(text: str) -> set[float]:
    """Numbers a page declares as conventions/parameters: ``<!-- conventions: 0.5 IC disk radius; … -->``."""
    out: set[float] = set()
    for m in _CONVENTIONS.finditer(text):
        for tok in _NUMBER.finditer(m.group(1)):
            v = _as_float(tok.group(0))
            if v is not None:
                out.add(abs(v))
    return out


def _matches(v: float, allowed: set[float]) -> bool:
    return any(math.isclose(v, a, rel_tol=1e-9, abs_tol=1e-12) for a in allowed)


def stray_numbers(text: str, allowed: set[float] = frozenset()) -> list[tuple[int, str]]:
    """stray_numbers(page Markdown, allowed numbers) -> [(line, token)] of the numbers its prose types by hand.

    A number in prose is fine when it comes through a ``[[study:path]]``
    reference, names a part of the paper or site (Fig. 2, Eq. (3)), is a
    small integer (≤ ``SMALL_INT``: a count, a panel, an exponent), is in
    ``allowed`` (the study's parameters, the paper's own values), or is
    declared on the page in a ``<!-- conventions: … -->`` comment (with its
    reason). Everything else is a result typed by hand, or a number nobody
    can trace: listed here.
    """
    allowed = set(allowed) | declared_conventions(text)
    body = prose(text)
    out = []
    for m in _NUMBER.finditer(body):
        tok = m.group(0)
        v = _as_float(tok)
        if v is None:
            continue
        v = abs(v)
        if v == int(v) and v <= SMALL_INT and not re.search(r"[.,eE]", tok.lstrip("+-−")):
            continue
        if _matches(v, allowed) or (
            tok.endswith(tuple("⁰¹²³⁴⁵⁶⁷⁸⁹")) and _matches(v, {10.0**k for k in range(-20, 21)})
        ):
            continue
        out.append((body.count("\n", 0, m.start()) + 1, tok))
    return out


def _paper_values(obj) -> set[float]:
    """The numbers a numbers JSON holds as the paper's (``paper`` keys and fields, at any depth)."""
    out: set[float] = set()
    if isinstance(obj, dict):
        for k, v in obj.items():
            out |= numbers_in(v) if k in ("paper", "paper_value", "paper_values") else _paper_values(v)
    elif isinstance(obj, list):
        for v in obj:
            out |= _paper_values(v)
    return out


def study_conventions(root: Path, study: str) -> set[float]:
    """The numbers a study page may type by hand: its parameters (``studies/<study>/study.toml``, every scale,
    and ``studies/conventions.toml``) and the paper's values its JSON records (both scales)."""

    out: set[float] = set()
    root = Path(root)
    for toml in (root / "studies" / study / "study.toml", root / "studies" / "conventions.toml"):
        if toml.is_file():
            out |= numbers_in(tomllib.loads(toml.read_text()))
    for scale in ("quick", "paper"):
        path = assets_dir(root, scale) / f"{study}.json"
        if path.is_file():
            out |= _paper_values(_load(str(path)))
    return {abs(v) for v in out}


# -- readings typed by hand (hhscatter.publish.readings writes them) ---------------------------------------------------------------------------------------
#: the words of a comparative or qualitative reading of results: verdicts and qualities (agrees, approaches,
#: monotone, holds, never, …) and comparisons (closer, farther, lies below/above the …, twice as, larger than,
#: exceeds, better, worse, differs from, only the … does, all within, none (…), consistent) and their hedges (hardly,
#: roughly, nearly, essentially, clearly, slightly, close to, about the same, much or far below/above/larger …, well
#: below/above; "crosses it": a value on both sides of another)
READING_WORDS = re.compile(
    r"\b(?:agrees?|agreed|disagrees?|approach(?:es|ing)?|monoton\w*|within a factor|holds|never|always|"
    r"best|worst|consistent(?:ly)? with|compatible with|in line with|as predicted|confirm(?:s|ed)?|match(?:es|ed)?|"
    r"tracks?|parts? near|(?:over|under)estimat\w*|everywhere|at every (?:energy|scan energy|E)|"
    r"closer|farther|further\s+from|(?:lies?|is|are|falls?|drops?|stays?|sits?)\s+(?:(?:well|far|just|slightly)\s+)?"
    r"(?:below|above)\s+the|above\s+the\s+paper's|twice\s+as|half\s+as|"
    r"(?:higher|lower|larger|smaller|greater|faster|slower|fewer)\s+than|exceed(?:s|ed|ing)?|better|worse|"
    r"only\s+(?:as|the\s+\S+(?:\s+\S+)?\s+(?:does|do|is|are|holds?))|all\s+within|none\s+(?=\()|"
    r"(?:in)?consistent(?:ly)?|differs?\s+from|no\s+[\w-]+(?:\s+[\w-]+)?\s+(?:row|point|cell|value)s?\s+differs?|"
    r"(?:several|a\s+few|many)\s+σ|σ\s+from\s+zero|by\s+up\s+to(?:\s+about)?\s+\d+(?:\.\d+)?\s*σ|"
    r"within\s+(?:its|their)\s+errors?|the\s+same\s+for\s+(?:r|E|γ|every|all\s+(?!systems))\S*|"
    r"times\s+as\s+(?:often|many|much|large|fast)|of\s+similar\s+size|"
    r"not\s+the\s+picture|times\s+(?:narrower|wider)|(?:is|are)\s+(?:narrower|wider)|cheaper|costlier|"
    r"explains?\s+most|"
    r"hardly|cross(?:es|ed)\s+(?:it|them|fig\d\S*|the\s+(?:measured|predicted|prediction|reference|paper's|fitted|other))|"
    r"roughly|nearly|essentially|clearly|barely|almost|slightly|about\s+the\s+same|close\s+to|"
    r"(?:much|far)\s+(?:below|above|closer|farther|wider|narrower|larger|smaller|longer|shorter|higher|lower|finer|"
    r"coarser|deeper|better|worse|more|less|from|apart)|(?<!the\s)well\s+(?:below|above))"
    r"(?!\w)",
    re.I,
)
_PROSE = re.compile(r"<!--\s*prose:(.*?)-->", re.S)
_QUOTE = re.compile(r"\"[^\"]*\"|“[^”]*”")


def typed_readings(text: str) -> list[tuple[int, str]]:
    """typed_readings(page Markdown) -> [(line, phrase)] of the reading words its prose types by hand.

    Not counted: ``[[…]]`` references (numbers and readings), code, HTML comments, quotes of the paper ("…"), and
    the phrases a page declares as explanation or definition in a ``<!-- prose: "phrase"; "phrase" -->`` comment.

    Examples
    --------
    >>> typed_readings('The ratio approaches 1. The paper says "μ approaches 1". [[reading:noise.kramers]]')
    [(1, 'approaches')]
    >>> typed_readings('<!-- prose: "never leave" -->\\nOrbits in the well can never leave.')
    []
    """
    declared = [p.strip() for m in _PROSE.finditer(text) for p in re.findall(r"\"([^\"]+)\"", m.group(1))]
    body = prose(text)
    chars = list(body)
    for rx in [_QUOTE] + [re.compile(re.escape(p)) for p in declared]:
        for m in rx.finditer("".join(chars)):
            for i in range(*m.span()):
                if chars[i] != "\n":
                    chars[i] = " "
    body = "".join(chars)
    return [(body.count("\n", 0, m.start()) + 1, m.group(0)) for m in READING_WORDS.finditer(body)]
