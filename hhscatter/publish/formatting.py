"""Numbers as text: the one ``value ± err`` formatter and the one paper-vs-ours table, for the report, the docs
and the figures.

* :func:`format_value_err` — ``v ± err`` rounded to the uncertainty (the
  particle-data convention: one significant digit of the error, two when it
  starts with 1 or 2; v to the same decimal place);
* :func:`format_number` — a number alone (4 significant digits);
* :func:`format_value` — any leaf of a study's numbers JSON (``{value, err}``,
  ``{value, lo, hi}``, short lists, scalars);
* :func:`comparison_table` — the Markdown table of a study's
  ``paper_comparison`` rows (with a study column for several studies);
* :func:`escape_table_bars` — ``|x|`` inside the cells of a Markdown table
  written by hand (e.g. ``|ΔH|`` in the benchmark summaries) escaped, so that
  a Markdown parser sees as many cells as the header; :func:`embed_markdown`
  — a document written to stand alone (a benchmark summary) made fit to be
  embedded in another: headings demoted, plain-text tables fenced, bars escaped;
* :func:`markdown_to_html` — Python-Markdown with the extensions the report needs.
"""

from __future__ import annotations

import math
import re

from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction.verdicts import row_bound, row_verdict

__all__ = [
    "comparison_table",
    "embed_markdown",
    "escape_table_bars",
    "formula_stars",
    "format_leaf",
    "keep_together",
    "format_number",
    "format_value",
    "format_value_err",
    "leaf_bound",
    "markdown_to_html",
    "md_cell",
    "scripts_to_html",
    "split_wide_tables",
    "typographic_minus",
]


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def format_number(v, sig: int = 4, *, html: bool = False) -> str:
    """format_number(v, sig=4, *, html=False) -> v to ``sig`` significant digits; "—" for None.

    Integers are written in full, booleans as true/false. With ``html``,
    magnitudes outside [1e-3, 1e5) are written a×10<sup>b</sup> (web pages),
    otherwise in Python's e-notation (plain text, figures).
    """
    if v is None:
        return "—"
    if isinstance(v, str):
        return v
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if not _is_num(v):
        return str(v)
    v = float(v)
    if not math.isfinite(v):
        return str(v)
    if v == 0:
        return "0"
    if html and not 1e-3 <= abs(v) < 1e5:
        m, e = f"{v:.{sig - 1}e}".split("e")
        return f"{m}×10<sup>{int(e)}</sup>"
    return f"{v:.{sig}g}"


def format_value_err(v, err=None, *, sep: str = " ± ", html: bool = False) -> str:
    """format_value_err(v, err=None, *, sep=" ± ", html=False) -> "v ± err" rounded to the uncertainty.

    One significant digit of ``err``, two when it starts with 1 or 2 (e.g.
    0.912 ± 0.003, 0.310 ± 0.012, 152 ± 7); v to the same decimal place.
    Very large or very small values: "v ± e" in e-notation (2.5e-14 ± 1.0e-15),
    or with ``html`` (web pages) in the notation of :func:`format_number`'s
    ``html``, one power of ten for both: (2.50 ± 0.10)×10<sup>-14</sup>.
    Without a usable error (None, NaN, < 0) the value alone; so with an error of
    exactly 0 (a number exact by construction, as a reference against itself,
    or a count of 0 recorded without its bound), never "± 0": a count of 0 with
    its bound is written by :func:`format_bound`. ``sep``: e.g. ``r" \\pm "``
    inside the LaTeX labels of figures.

    >>> format_value_err(0.0, 0.0), format_value_err(0.5, 0.0), format_value_err(0.912, 0.003)
    ('0', '0.5', '0.912 ± 0.003')
    >>> format_value_err(2.63e-6, 6.3e-8), format_value_err(2.63e-6, 6.3e-8, html=True)
    ('2.63e-06 ± 6.3e-08', '(2.63 ± 0.06)×10<sup>-6</sup>')
    """
    if not _is_num(v) or (isinstance(v, float) and not math.isfinite(v)):
        return format_number(v, html=html)
    if not _is_num(err) or not math.isfinite(err) or err <= 0:  # no error to write (never "± 0")
        return format_number(v, html=html)
    exp10 = int(math.floor(math.log10(err)))
    digits = max(0, -exp10 + (1 if err / 10.0**exp10 < 3 else 0))
    if html and (abs(v) >= 1e4 or digits > 5):  # one power of ten, as format_number writes it on a page
        k = int(math.floor(math.log10(abs(v) if v != 0 else err)))
        return f"({format_value_err(v / 10.0**k, err / 10.0**k, sep=sep)})×10<sup>{k}</sup>"
    if abs(v) >= 1e4 or digits > 5:
        return f"{v:.3g}{sep}{err:.1e}" if v != 0 else f"0{sep}{err:.1e}"
    return f"{v:.{digits}f}{sep}{err:.{digits}f}"


def format_bound(upper=None, lower=None, cl: float = 0.95, *, pct: bool = False) -> str:
    """format_bound(upper=None, lower=None, cl=0.95, pct=False) -> a one-sided bound as pages write it: a count
    of 0 as "< bound (95 %)", a count of all as "> bound (95 %)" (2 significant digits; ``pct``: in per cent).

    >>> format_bound(2.995e-4), format_bound(2.995e-4, pct=True), format_bound(lower=0.9985, cl=0.9)
    ('< 3.0e-4 (95 %)', '< 0.030 % (95 %)', '> 0.9985 (90 %)')
    """
    if (upper is None) == (lower is None):
        raise ValueError("give one bound: upper (a count of 0) or lower (a count of all)")
    b, sign = (upper, "<") if upper is not None else (lower, ">")
    level = f"({100 * cl:g} %)"
    if sign == ">" and b > 0.9:  # 2 significant digits of the distance to 1
        return f"{sign} {b:.{1 - math.floor(math.log10(1 - b))}f} {level}"
    v = 100 * b if pct else b
    if not pct and v < 1e-3:
        m, e = f"{v:.1e}".split("e")
        return f"{sign} {m}e{int(e)} {level}"
    text = f"{v:.{max(0, 1 - math.floor(math.log10(v)))}f}"
    return f"{sign} {text}{' %' if pct else ''} {level}"


def leaf_bound(leaf) -> dict | None:
    """leaf_bound(numbers-JSON leaf) -> {"upper" or "lower": bound, "cl": level} of a ``{value, …}`` leaf that is a
    fraction counted at 0 (or at all): its own ``upper`` / ``lower`` and ``cl``
    (:meth:`~hhscatter.analysis.stats.intervals.BoundedFraction.record`), else from its number of trials ``n``, by
    the rule of the paper-vs-ours rows (:func:`hhscatter.reproduction.verdicts.row_bound`); None for any other leaf.

    >>> leaf_bound({"value": 0.0, "lo": 0.0, "hi": 1.7e-5, "n": 60000})
    {'upper': 4.9928e-05, 'cl': 0.95}
    >>> leaf_bound({"value": 0.003, "lo": 0.0027, "hi": 0.0032, "n": 60000}) is None
    True
    """
    if not isinstance(leaf, dict) or not _is_num(leaf.get("value")):
        return None
    row = {"ours": leaf["value"], "n": leaf.get("n")}
    row.update({f"ours_{k}": leaf[k] for k in ("upper", "lower", "cl") if k in leaf})
    return row_bound(row)


def format_value(v, *, html: bool = False) -> str:
    """format_value(v) -> text of one numbers-JSON leaf: {value, err} (or a
    :class:`~hhscatter.analysis.stats.measured.Measured`) → v ± err, {value, lo, hi} → v [lo, hi], a fraction
    counted at 0 or at all (:func:`leaf_bound`) → its one-sided bound "< b (95 %)", short lists element by element,
    longer lists and tables by their size.

    >>> format_value(Measured(0.9123, 0.0031).to_dict()), format_value(Measured(0.9123, 0.0031)), format_value(Measured(0.9123))
    ('0.912 ± 0.003', '0.912 ± 0.003', '0.9123')
    >>> format_value({"value": 0.0, "lo": 0.0, "hi": 1.7e-5, "n": 60000})
    '< 5.0e-5 (95 %)'
    """
    if isinstance(v, Measured):
        v = v.to_dict()
    if isinstance(v, dict) and "value" in v:
        if v.get("value") is None:
            return "—"
        bound = leaf_bound(v)
        if bound is not None:
            return format_bound(**bound)
        if _is_num(v.get("lo")) and _is_num(v.get("hi")):
            return (
                f"{format_number(v['value'], html=html)} [{format_number(v['lo'], html=html)}, "
                f"{format_number(v['hi'], html=html)}]"
            )
        return format_value_err(v.get("value"), v.get("err"))
    if isinstance(v, (list, tuple)):
        if len(v) <= 8 and all(_is_num(x) or isinstance(x, str) or x is None for x in v):
            return "[" + ", ".join(format_number(x, html=html) for x in v) + "]"
        if len(v) <= 8 and all(isinstance(x, dict) and "value" in x for x in v):
            return "[" + ", ".join(format_value(x, html=html) for x in v) + "]"
        if len(v) <= 4 and all(isinstance(x, (list, tuple)) and len(x) <= 4 for x in v):
            return "[" + ", ".join(format_value(x, html=html) for x in v) + "]"
        return f"*({len(v)} entries; see the JSON)*"
    if isinstance(v, dict):
        return f"*({len(v)} fields; see the JSON)*"
    return format_number(v, html=html)


REFERENCE = "reference"
_DIFFERENCE_NAMES = ("_vs_ref", "_from_ref", "difference", "shift")


def format_leaf(key: str, v, *, html: bool = False) -> str:
    """format_leaf(dotted key, value) -> :func:`format_value` of one numbers-JSON leaf, except a difference to a
    reference measured on the reference itself: a ``{value: 0, err: 0}`` whose name says it is a difference or
    shift to a reference (ending ``_vs_ref`` or ``_from_ref``, or naming a ``difference`` or ``shift``) reads
    "reference", never a measured 0.

    >>> format_leaf("kappa.E=0.25.r_esc=1.03.shift_vs_ref", Measured(0.0, 0.0))
    'reference'
    >>> format_leaf("kappa.E=0.25.r_esc=1.1.shift_vs_ref", Measured(-0.00207, 0.00118))
    '-0.0021 ± 0.0012'
    >>> format_leaf("returns.n_returned", Measured(0.0, 0.0).to_dict())
    '0'
    """
    name = str(key).rsplit(".", 1)[-1]
    if isinstance(v, Measured):
        v = v.to_dict()
    if (
        isinstance(v, dict)
        and v.get("value") == 0
        and v.get("err") == 0
        and _is_num(v.get("value"))
        and _is_num(v.get("err"))
        and any(part in name for part in _DIFFERENCE_NAMES)
    ):
        return REFERENCE
    return format_value(v, html=html)


def md_cell(s) -> str:
    """Text for one cell of a Markdown table: bars and stars escaped (a formula's t* stays a star, never emphasis),
    on one line.

    Examples
    --------
    >>> print(md_cell("d(μ_c^E(t*)), E(t*) = 1.5 E_c | x"))
    d(μ_c^E(t\\*)), E(t\\*) = 1.5 E_c \\| x
    """
    return str(s).replace("|", "\\|").replace("*", "\\*").replace("\n", " ")


def ours_cell(row) -> str:
    """ours_cell(paper-vs-ours row) -> our number as printed: 'value ± err unit' (or the value as text); a fraction
    counted at 0 or at all as its one-sided bound (:func:`hhscatter.reproduction.verdicts.row_bound`).

    >>> ours_cell({"ours": 0.25, "err": 0.0137}), ours_cell({"ours": 0.0, "err": None, "n": 60000})
    ('0.250 ± 0.014', '< 5.0e-5 (95 %)')
    """
    unit = f" {row['unit']}" if row.get("unit") else ""
    ours = row.get("ours")
    bound = row_bound(row)
    if bound is not None:
        return format_bound(**bound) + unit
    return (format_value_err(ours, row.get("err")) if _is_num(ours) else format_value(ours)) + unit


def comparison_table(rows, *, study: bool = False, quantity=None, verdict=None, scale: str | None = None) -> str:
    """comparison_table(rows, *, study=False, quantity=None, verdict=None, scale=None) -> Markdown table.

    ``rows``: paper-vs-ours rows {quantity, ours, err, paper, unit, verdict,
    note} (and ``study`` for a leading study column). ``quantity`` and
    ``verdict`` may map a row / a verdict to the text of their cell (e.g. a
    link, or a coloured span in HTML). Columns: quantity, ours, convention
    (how our number was made, when a row says), paper, verdict, note. The
    verdict cell is the one rule's
    (:func:`hhscatter.reproduction.verdicts.row_verdict`, both
    uncertainties; none at the tiny ``scale``), whatever rule the row was
    written with.
    """
    conv = any(r.get("convention") for r in rows)
    head = ["study"] * study + ["quantity", "ours"] + ["convention (ours)"] * conv + ["paper", "verdict", "note"]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        v = row_verdict(r, r.get("scale", scale))
        cells = (
            [r.get("study", "")] * study
            + [quantity(r) if quantity else md_cell(r.get("quantity", "")), md_cell(ours_cell(r))]
            + [md_cell(r.get("convention") or "—")] * conv
            + [
                md_cell(format_value(r.get("paper"))),
                verdict(v) if verdict else md_cell(v),
                md_cell(r.get("note") or ""),
            ]
        )
        out.append("| " + " | ".join(str(c) for c in cells) + " |")
    if not rows:
        out.append("| " + " | ".join(["—"] * study + ["no study outputs found", "", "", "", ""] + [""] * conv) + " |")
    return "\n".join(out) + "\n"


_SEPARATOR = re.compile(r"^\|[\s:|-]+\|\s*$")


def _escape_row(line: str) -> str:
    """Escape the bars of |x| inside a table row: a cell separator has spaces (or the line end) on both sides."""
    if _SEPARATOR.match(line):
        return line
    out = []
    end = len(line.rstrip()) - 1
    for i, ch in enumerate(line):
        if ch == "|" and 0 < i < end and (line[i - 1] == "\\" or not (line[i - 1] == " " and line[i + 1] == " ")):
            out.append(ch if line[i - 1] == "\\" else "\\|")
        else:
            out.append(ch)
    return "".join(out)


def escape_table_bars(text: str) -> str:
    """escape_table_bars(markdown) -> the same text with ``|x|`` inside table cells escaped (``\\|x\\|``)."""
    return "\n".join(_escape_row(ln) if ln.startswith("|") else ln for ln in text.split("\n"))


def _fence_plain_tables(text: str) -> str:
    """Fence plain-text tables (e.g. pandas ``to_string``: a paragraph whose first line is indented)."""
    out, block, in_fence = [], [], False

    def flush():
        if block and block[0].startswith("  ") and len(block) > 1 and not block[0].lstrip().startswith(("-", "*", "|")):
            out.extend(["```text", *block, "```"])
        else:
            out.extend(block)
        block.clear()

    for line in text.splitlines():
        if line.lstrip().startswith(("```", "~~~")):
            flush()
            in_fence = not in_fence
            out.append(line)
        elif in_fence:
            out.append(line)
        elif line.strip():
            block.append(line)
        else:
            flush()
            out.append(line)
    flush()
    return "\n".join(out) + "\n"


_CELL_SPLIT = re.compile(r"(?<!\\)\|")
_NUMERIC_CELL = re.compile(r"^[\s\d.,+−\-–×^()e%≤<>~]*$|^—$|^$")


def _cells(line: str) -> list[str]:
    return [c.strip() for c in _CELL_SPLIT.split(line.strip())[1:-1]]


def _column_shares(head: list[str], keys: int, room: int) -> list[list[int]]:
    """The other columns of a table (after ``keys``) in shares of at most ``room`` columns; a percentile column
    ("p99", "p99 short") stays with the column before it, whose quantity it qualifies."""
    groups: list[list[int]] = []
    for j in range(keys, len(head)):
        if groups and re.match(r"p\d+\b", head[j]):
            groups[-1].append(j)
        else:
            groups.append([j])
    shares: list[list[int]] = []
    for g in groups:
        if shares and len(shares[-1]) + len(g) <= room:
            shares[-1] += g
        else:
            shares.append(list(g))
    return shares


def split_wide_tables(text: str, max_cols: int = 8) -> str:
    """split_wide_tables(Markdown, max_cols=8) -> the text with every table of more than ``max_cols`` columns
    written as several tables of the same rows, each with the table's leading label columns (those holding text,
    at most 4) and a share of its other columns (a percentile column kept with the one before it), so that none
    is wider than a page's text column.

    Examples
    --------
    >>> t = "| a | b | c | d |\\n|---|---|---|---|\\n| x | 1 | 2 | 3 |"
    >>> print(split_wide_tables(t, max_cols=3))
    | a | b | c |
    |---|---|---|
    | x | 1 | 2 |
    <BLANKLINE>
    The same rows, further columns:
    <BLANKLINE>
    | a | d |
    |---|---|
    | x | 3 |
    """
    lines, out, i = text.split("\n"), [], 0
    while i < len(lines):
        j = i
        while j < len(lines) and lines[j].lstrip().startswith("|"):
            j += 1
        block = lines[i:j]
        if (
            len(block) >= 2
            and re.fullmatch(r"\s*\|(\s*:?-{3,}:?\s*\|)+\s*", block[1])
            and len(_cells(block[0])) > max_cols
        ):
            rows = [_cells(r) for r in block]
            n = len(rows[0])
            data = [r for k, r in enumerate(rows) if k != 1]
            keys = 0
            while keys < min(4, n - 1) and any(not _NUMERIC_CELL.match(r[keys]) for r in data[1:] if keys < len(r)):
                keys += 1
            keys = max(keys, 1)
            parts = []
            for share in _column_shares(rows[0], keys, max(1, max_cols - keys)):
                cols = list(range(keys)) + share
                part = [
                    "| " + " | ".join(r[c] if c < len(r) else "" for c in cols) + " |"
                    if k != 1
                    else "|---" * len(cols) + "|"
                    for k, r in enumerate(rows)
                ]
                parts.append("\n".join(part))
            out.append("\n\nThe same rows, further columns:\n\n".join(parts))
            i = j
            continue
        if j > i:
            out.extend(block)
            i = j
        else:
            out.append(lines[i])
            i += 1
    return "\n".join(out)


def embed_markdown(text: str, demote: int = 2) -> str:
    """embed_markdown(text, demote=2) -> a standalone Markdown document fit to be embedded in another.

    Plain-text tables fenced, ``|x|`` inside table cells escaped, tables wider than a page's text column split
    (:func:`split_wide_tables`), headings (levels 1–4, outside code) demoted by ``demote`` levels.
    """
    text = split_wide_tables(escape_table_bars(_fence_plain_tables(text)))
    out, in_fence = [], False
    for line in text.split("\n"):
        if line.lstrip().startswith(("```", "~~~")):
            in_fence = not in_fence
        elif not in_fence:
            line = re.sub(r"^(#{1,4}) ", lambda m: "#" * (len(m.group(1)) + demote) + " ", line)
        out.append(line)
    return "\n".join(out)


def markdown_to_html(text: str) -> str:
    """markdown_to_html(text) -> HTML by Python-Markdown (tables, fenced code, attribute lists, raw HTML kept)."""
    import markdown  # deferred: markdown loads on first use

    return markdown.markdown(
        text, extensions=["tables", "fenced_code", "attr_list", "sane_lists"], output_format="html"
    )


def scripts_to_html(text: str) -> str:
    """scripts_to_html(text) -> ``x^{a}`` as ``x<sup>a</sup>`` and ``x_{a}`` as ``x<sub>a</sub>`` (braces matched,
    nested ones converted too; anything else unchanged).

    The package's docstrings and the pages write formulas as plain text that ``help()`` reads (``E0 e^{−μγt}``,
    ``μ_c^{E1}``, ``Σ_{s∈i}``); the docs set them as superscripts and subscripts, never as raw braces.

    Examples
    --------
    >>> scripts_to_html("E0 e^{−μγt}, ∫_{E_c}^{E0} and x^2")
    'E0 e<sup>−μγt</sup>, ∫<sub>E_c</sub><sup>E0</sup> and x^2'
    """
    out, i = [], 0
    while i < len(text):
        if text[i] in "^_" and text.startswith("{", i + 1):
            depth, j = 0, i + 1
            while j < len(text):
                depth += {"{": 1, "}": -1}.get(text[j], 0)
                if depth == 0:
                    break
                j += 1
            if depth == 0:
                tag = "sup" if text[i] == "^" else "sub"
                out.append(f"<{tag}>{scripts_to_html(text[i + 2 : j])}</{tag}>")
                i = j + 1
                continue
        out.append(text[i])
        i += 1
    return "".join(out)


#: what typographic_minus leaves as written: fenced code, code spans, maths, HTML comments and tags (their
#: attributes); a tag opens with a name ("<span", "</td"), so that "r < 1 … 17 < t" is text, not a tag
_VERBATIM = re.compile(r"```.*?```|`[^`\n]*`|\$\$.*?\$\$|\$[^$\n]*\$|\\\(.*?\\\)|<!--.*?-->|</?[A-Za-z][^<>\n]*>", re.S)
#: a hyphen as the sign of a number: after a space, an opening bracket, "=", ":", ";", "(" or ">"; not "x-1",
#: "E0-E_c"; and the sign of an exponent ("2.6e-05")
_SIGN = re.compile(r"(?<![\w.\-/])-(?=\.?\d)|(?<=\d[eE])-(?=\d)")


def typographic_minus(text: str) -> str:
    """The generated text with a negative number's hyphen written as the minus sign "−" (as the verdicts and the
    rendered numbers write it); fenced code, code spans, maths and HTML tags are left as written. The docs' generated tables
    and the reproduction report pass through it.

    Examples
    --------
    >>> typographic_minus("| -0.26 ± 0.19 | (z = -1.1) | `grid[-1]` | x-1 | 10<sup>-10</sup> |")
    '| −0.26 ± 0.19 | (z = −1.1) | `grid[-1]` | x-1 | 10<sup>−10</sup> |'
    >>> typographic_minus("| r < 1 | 2.6e-05 ± 4e-07 | -0.003 [-0.010, +0.002] | <span>-1.1</span> |")
    '| r < 1 | 2.6e−05 ± 4e−07 | −0.003 [−0.010, +0.002] | <span>−1.1</span> |'
    """
    out, last = [], 0
    for m in _VERBATIM.finditer(text):
        out += [_SIGN.sub("−", text[last : m.start()]), m.group(0)]
        last = m.end()
    return "".join(out) + _SIGN.sub("−", text[last:])


#: the stars of a plain-text formula: an operator between two terms ("0.5*(x**2", "x**2*y") …
_OPERATOR_STAR = re.compile(r"(?<=[\w)])\*{1,2}(?=[\w(])")
#: … and the mark of a one-letter symbol ("t*", "E(t*)", "τ*,"), not the closing star of an emphasised word
_SYMBOL_STAR = re.compile(r"(?<![\w\\*])([^\W\d_])\*(?![\w*])")


def formula_stars(text: str) -> str:
    r"""formula_stars(markdown) -> the same Markdown with the stars of plain-text formulas escaped, so that a
    Markdown parser shows them instead of reading two of them as emphasis: an operator star between two terms
    (``0.5*(x**2 + y**2)``) and the star of a one-letter symbol (``E(t*)``, ``τ*``). Code, maths, HTML and
    stars already escaped are left as written, and so is the emphasis of words (``*a caption*``, ``**bold**``).

    Examples
    --------
    >>> text = "E(t*) = E1; not τ*, the onset; *a caption*; **bold**; `t*x*`"
    >>> print(formula_stars(text))
    E(t\*) = E1; not τ\*, the onset; *a caption*; **bold**; `t*x*`
    >>> formula_stars(formula_stars(text)) == formula_stars(text)  # an escaped star stays as it is
    True
    >>> print(formula_stars("declared '0.5*(x**2 + y**2) - y**3/3'"))
    declared '0.5\*(x\*\*2 + y\*\*2) - y\*\*3/3'
    """

    def escape(part: str) -> str:
        part = _OPERATOR_STAR.sub(lambda m: m.group(0).replace("*", "\\*"), part)
        return _SYMBOL_STAR.sub(lambda m: m.group(1) + "\\*", part)

    out, last = [], 0
    for m in _VERBATIM.finditer(text):
        out += [escape(text[last : m.start()]), m.group(0)]
        last = m.end()
    return "".join(out) + escape(text[last:])


#: inside a table row: the space after "±" or a comparison sign before its number, and before the "%" of a number
_GLUE = re.compile(r"(?<=[±<>≤≥]) (?=[\d−+.])|(?<=\d) (?=%)")
_TABLE_ROW = re.compile(r"^[ \t]*\|.*$", re.M)


def keep_together(text: str) -> str:
    r"""keep_together(markdown) -> its table rows with a no-break space where a narrow column must not break a number
    from its sign or unit: after "±" and after "<", ">", "≤", "≥" before a number, and between a number and "%". A
    cell then wraps as "0.9338" / "± 0.0025" or "< 3.0e−4" / "(95 %)", never "± " / "0.0025" or "(95" / "%)". Code
    and maths are left as written; prose outside tables too.

    Examples
    --------
    >>> keep_together("| 0.9338 ± 0.0025 | < 3.0e−4 (95 %) | `a < 1` |\nx ± 1 %").replace("\u00a0", "~")
    '| 0.9338 ±~0.0025 | <~3.0e−4 (95~%) | `a < 1` |\nx ± 1 %'
    """

    def row(m):
        line, out, last = m.group(0), [], 0
        for v in _VERBATIM.finditer(line):
            out += [_GLUE.sub("\u00a0", line[last : v.start()]), v.group(0)]
            last = v.end()
        return "".join(out) + _GLUE.sub("\u00a0", line[last:])

    return _TABLE_ROW.sub(row, text)
