"""Reproduction report: every figure and number of the paper beside ours.

``build_report(scale='quick', out=None)`` reads what the studies left on disk
(``studies/<name>/out/<scale>/<name>.json`` and ``<name>.png``; the benchmark
summary under ``benchmarks/out/``) and writes the report as Markdown
beside its PNG files and, from the same Markdown rendered by Python-Markdown,
one self-contained HTML file (figures embedded as data URIs). It computes no
physics: every number comes from a study's numbers JSON, so the report and
the study outputs cannot disagree. Numbers and the paper-vs-ours tables are
formatted by :mod:`hhscatter.publish.formatting`, as in the docs.
"""

from __future__ import annotations

import argparse
import base64
import datetime as _dt
import html
import json
import os
import re
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from hhscatter.analysis.stats.verdicts import verdict_class
from hhscatter.errors import StudyError
from hhscatter.publish.formatting import (
    comparison_table,
    embed_markdown,
    format_value,
    formula_stars,
    markdown_to_html,
    md_cell,
    scripts_to_html,
    typographic_minus,
)
from hhscatter.publish.words import in_glossary_words
from hhscatter.reproduction.escape_criterion import with_return_counts
from hhscatter.reproduction.fig2 import with_cmeasure_references
from hhscatter.reproduction.verdicts import RULE, row_verdict
from hhscatter.studies import load_study, studies_root
from hhscatter.studies.cost import summary, totals
from hhscatter.studies.graph import GraphError, scales
from hhscatter.studies.graph import studies as study_folders
from hhscatter.studies.jsonio import write_json_atomic


@dataclass
class Section:
    key: str
    title: str
    caption: str
    figure: Path | None
    numbers: dict | None
    paper: str = ""  # the paper's figure this study reproduces ("" for a study beyond the paper)
    cost: dict | None = None  # the stage costs (hhscatter.studies.cost), if recorded


def headline_numbers(numbers: dict, limit: int = 40) -> list[tuple[str, str]]:
    """headline_numbers(numbers) -> [(name, formatted)] of the scalar and value±err entries of a numbers JSON."""
    skip = {"study", "scale", "paper_comparison", "config", "provenance", "raw_runs", "made_from", "sha256"}
    rows = []

    def walk(prefix, d, depth):
        for k, v in d.items():
            if k in skip or len(rows) >= limit:
                continue
            name = f"{prefix}{k}"
            if isinstance(v, dict) and "value" in v:
                rows.append((name, format_value(v)))
            elif isinstance(v, (int, float, bool)) or (isinstance(v, str) and len(v) < 80):
                rows.append((name, format_value(v)))
            elif isinstance(v, dict) and depth < 1:
                walk(f"{name}.", v, depth + 1)

    walk("", numbers, 0)
    return rows


def committed_assets(root: Path, scale: str) -> Path:
    """committed_assets(studies root, scale) -> the docs folder of the committed study outputs at ``scale``
    (``docs/studies/assets`` for quick, ``docs/studies/assets/<scale>`` otherwise; docs/gen_studies.py)."""
    base = Path(root).parent / "docs" / "studies" / "assets"
    return base if scale == "quick" else base / scale


def _study_files(root: Path, name: str, scale: str):
    """(figure, numbers, cost) paths of a study: its out/<scale>/ if it made them here, else the committed copies."""
    out = root / name / "out" / scale
    assets = committed_assets(root, scale)
    pick = []
    for here, there in (
        (out / f"{name}.png", assets / f"{name}.png"),
        (out / f"{name}.json", assets / f"{name}.json"),
        (out / "cost.json", assets / f"{name}.cost.json"),
    ):
        pick.append(here if here.exists() else there if there.exists() else None)
    return tuple(pick)


def _checked_root(root: Path | None, scale: str) -> Path:
    """The studies folder (``root``, default the repository's), once ``scale`` is one its study.toml files declare
    (else :class:`~hhscatter.errors.StudyError`)."""
    root = Path(root) if root is not None else studies_root()
    try:
        known = scales(root)
    except GraphError as exc:
        raise StudyError(str(exc)) from None
    if scale not in known:
        raise StudyError(f"scale must be one of {known} (the scales the study.toml files declare), got {scale!r}")
    return root


def collect(scale: str = "quick", root: Path | None = None) -> list[Section]:
    """collect(scale, root=None) -> [Section], one per study folder of ``root`` (in dependency order).

    Titles and captions come from each study's ``[about]`` table; a study
    with ``paper = ""`` goes to the part beyond the paper. A study's outputs
    are read from ``studies/<name>/out/<scale>/`` when it made them on this
    machine, else from the committed copies in the docs (:func:`committed_assets`),
    so a report of the committed paper-scale results needs no simulation.

    Every numbers JSON is verified before it is used (:meth:`hhscatter.studies.Study.verify_numbers`): one edited
    after it was written, made from another study.toml, from other upstream numbers than those the report
    shows beside it, or (in a study's out/ folder) from other raw runs than those there, raises
    :class:`~hhscatter.studies.provenance.ProvenanceError` naming the file. An unknown ``scale`` raises
    :class:`~hhscatter.errors.StudyError`.
    """
    root = _checked_root(root, scale)
    sections = []
    for info in study_folders(root):
        fig, nums, cost = _study_files(root, info.name, scale)
        doc = json.loads(nums.read_text()) if nums else None
        if doc is not None:
            study = load_study(info.name, scale, root=root)
            study.verify_numbers(
                nums,
                doc,
                pick=lambda other: _study_files(root, other, scale)[1],
                raw=nums.parent == root / info.name / "out" / scale,
            )
            doc = with_return_counts(doc)  # rows written before they carried their count: from the record
            doc = with_cmeasure_references(doc)  # rows written before they carried their reference: from the record
            doc = in_glossary_words(doc)  # text written before the studies said "censored"
        sec = Section(info.name, info.title, info.summary, fig, doc, info.paper)
        sec.cost = json.loads(cost.read_text()) if cost else None
        sections.append(sec)
    return sections


def comparison_rows(sections) -> list[dict]:
    rows = []
    for s in sections:
        for r in (s.numbers or {}).get("paper_comparison", []):
            rows.append({"study": s.key, **r})
    return rows


_verdict_class = verdict_class  # agrees / differs / neither, by |z| when the verdict has one


def _img_uri(path: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(path.read_bytes()).decode()


def _provenance(sections):
    for s in sections:
        if s.numbers and "provenance" in s.numbers:
            return s.numbers["provenance"]
    return {}


def commits_line(sections) -> str:
    """commits_line(sections) -> "Numbers made at commit abc123 (fig1, fig2), def456-dirty (fig3) …".

    Each study's numbers carry the commit they were made at; one study's commit is not the report's. A
    ``-dirty`` commit is said in words: that run's work tree had uncommitted changes.
    """
    by = {}
    for s in sections:
        c = ((s.numbers or {}).get("provenance") or {}).get("git_commit")
        if c:
            by.setdefault(str(c), []).append(s.key)
    if not by:
        return ""
    parts = [
        f"`{c.split('-')[0][:12]}`{' (uncommitted changes)' if c.endswith('-dirty') else ''}: {', '.join(names)}"
        for c, names in sorted(by.items(), key=lambda kv: -len(kv[1]))
    ]
    return "Numbers made at commit " + "; ".join(parts) + "."


BENCH_PARTS = (
    ("bench", "Work–precision and throughput (`make bench`)"),
    ("stress", "Numerical stress tests (`make stress`)"),
)


def _bench(root: Path, name: str = "bench"):
    """The summary.md (or None) and PNGs of the full-scale benchmark/stress output of the repository of the studies
    folder ``root`` (``benchmarks/out/<name>/full/``), else of the copy committed in docs/benchmarks/assets/<name>/."""
    for out in (
        root.parent / "benchmarks" / "out" / name / "full",
        root.parent / "docs" / "benchmarks" / "assets" / name,
    ):
        md = out / "summary.md"
        if md.exists():
            return md, sorted(out.glob("*.png"))
    return None, []


def raw_runs_line(runs: dict) -> str:
    """raw_runs_line({key: {scene_hash, orbits, complete}}) -> one line naming the raw runs a study's numbers
    were made from, their completeness and scene hashes (checked by the analyze stage)."""
    parts = [
        f"`{k}` ({r.get('orbits') or '?'} orbits, {'complete' if r.get('complete') else 'INCOMPLETE'}, "
        f"scene {str(r.get('scene_hash'))[:10]}…)"
        for k, r in sorted(runs.items())
    ]
    return f"*Made from {len(runs)} raw run(s):* " + "; ".join(parts) + "."


def cost_rows(sections) -> list[dict]:
    """cost_rows(sections) -> one row per study with a cost record: wall and CPU hours, orbits, peak RSS (MB)."""
    rows = []
    for s in sections:
        if not s.cost:
            continue
        c = summary(s.cost)
        rows.append(
            {
                "study": s.key,
                "wall_h": c["wall_s"] / 3600,
                "cpu_h": c["cpu_s"] / 3600,
                "simulate_cpu_h": c["simulate_cpu_s"] / 3600,
                "orbits": c["orbits"],
                "rss_mb": c["rss_mb"],
            }
        )
    return rows


def cost_table(rows) -> str:
    """cost_table(rows of :func:`cost_rows`) -> Markdown table with a total row."""
    out = [
        "| study | wall (h) | CPU (h) | of which simulate (h) | orbits integrated | peak RSS per process (MB) |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        out.append(
            f"| {r['study']} | {r['wall_h']:.2f} | {r['cpu_h']:.2f} | {r['simulate_cpu_h']:.2f} | "
            f"{r['orbits']:.3g} | {r['rss_mb']:.0f} |"
        )
    if rows:
        out.append(
            f"| **total** | **{sum(r['wall_h'] for r in rows):.2f}** | **{sum(r['cpu_h'] for r in rows):.2f}** |"
            f" {sum(r['simulate_cpu_h'] for r in rows):.2f} | {sum(r['orbits'] for r in rows):.3g} | "
            f"{max(r['rss_mb'] for r in rows):.0f} |"
        )
    return "\n".join(out) + "\n"


def split_rows(rows, sections):
    """split_rows(rows, sections) -> (paper_rows, beyond_rows): rows of a paper figure's study with a number the
    paper states vs the rest."""
    of_paper = {s.key for s in sections if s.paper}
    paper = [r for r in rows if r["study"] in of_paper and r.get("paper") is not None]
    beyond = [r for r in rows if not (r["study"] in of_paper and r.get("paper") is not None)]
    return paper, beyond


def verdict_counts(rows) -> dict:
    counts = {"ok": 0, "bad": 0, "meh": 0, "": 0}
    for r in rows:
        counts[_verdict_class(row_verdict(r))] += 1
    return counts


def _count_line(rows):
    c = verdict_counts(rows)
    return f"{len(rows)} numbers: {c['ok']} agree, {c['bad']} differ, {c['meh'] + c['']} qualitative or not comparable."


def _rows_table(rows, html_verdicts: bool) -> str:
    """The paper-vs-ours rows of several studies (:func:`hhscatter.publish.formatting.comparison_table`); in the HTML
    flavour the verdicts are coloured spans."""

    def verdict(v):
        cls = _verdict_class(v)
        if html_verdicts and cls:  # a bar of the verdict ("|z| ≤ 2") escaped, as md_cell does: one cell
            return f'<span class="{cls}">{md_cell(html.escape(v))}</span>'
        return md_cell(v)

    return comparison_table(rows, study=True, verdict=verdict)


def render_markdown(sections, scale, root, image, *, html_verdicts: bool = False) -> str:
    """render_markdown(sections, scale, root, image) -> the report in Markdown.

    ``image(path, name)`` returns the link target of a figure (a file copied
    beside report.md, or a data URI for the HTML); ``html_verdicts`` colours
    the verdicts (for the HTML page).
    """
    paper_rows, beyond_rows = split_rows(comparison_rows(sections), sections)
    prov = _provenance(sections)
    lines = [
        f"# hhscatter reproduction report ({scale} scale)",
        "",
        "Reproduction of L. Burton, H. Dullin, E. G. Altmann, *Probabilistic description of dissipative "
        "chaotic scattering*, arXiv:2308.13555 (2023) (Hénon–Heiles with linear "
        "drag), with exact event times from heyoka's Taylor integrator. Every number below is read from the "
        "studies' numbers JSON files; see `make help` for the targets that made them. Verdicts: "
        f"{RULE} The paper's numbers are in the authors' "
        'convention; the column *convention (ours)* says how each of ours was made ("authors\'" marks a row '
        "made in the authors' own convention). \"Differs\" is kept for differences that survive the authors' "
        'convention; one that does not reads "differs in our convention only" and is not counted as a '
        "difference.",
        "",
        f"Generated {_dt.datetime.now(_dt.UTC):%Y-%m-%d %H:%M UTC}; "
        f"versions: {', '.join(f'{k} {v}' for k, v in prov.items() if isinstance(v, str) and k != 'git_commit')}. "
        f"{commits_line(sections)}",
        "",
        "## The paper's numbers beside ours",
        "",
        _count_line(paper_rows),
        "",
        _rows_table(paper_rows, html_verdicts),
        "",
        "## Beyond the paper: checks and numbers the paper does not state",
        "",
        _count_line(beyond_rows),
        "",
        _rows_table(beyond_rows, html_verdicts),
    ]
    costs = cost_rows(sections)
    if costs:
        lines += [
            "",
            f"## What it cost ({scale} scale)",
            "",
            "Measured by the study stages (`studies/<name>/out/<scale>/cost.json`): wall and CPU time of "
            "simulate + analyze + plot (CPU includes the worker processes), orbits integrated, and the peak "
            "resident memory of one process.",
            "",
            cost_table(costs),
        ]
    for group, of_paper in (("Figures of the paper", True), ("Beyond the paper", False)):
        lines += ["", f"## {group}", ""]
        for s in (s for s in sections if bool(s.paper) == of_paper):
            lines += [f"### {s.title} (`make {s.key}`)", "", f"*{s.caption}*" if s.caption else "", ""]
            if s.figure:
                lines += [f"![{s.title}]({image(s.figure, f'{s.key}.png')})", ""]
            else:
                lines += [f"*Not generated yet: run `make {s.key} SCALE={scale}`.*", ""]
            if s.numbers and s.numbers.get("raw_runs"):
                lines += [raw_runs_line(s.numbers["raw_runs"]), ""]
            if s.numbers:
                lines += ["| number | value |", "|---|---|"]
                lines += [f"| {md_cell(k)} | {md_cell(v)} |" for k, v in headline_numbers(s.numbers)]
                lines.append("")
    lines = ["\n".join(lines)]
    for name, title in BENCH_PARTS:
        md, pngs = _bench(root, name)
        lines += [f"## {title}", ""]
        if md:
            # a summary written for its own folder: headings demoted, plain tables fenced, |x| in cells escaped
            lines += [embed_markdown(md.read_text()), ""]
            lines += [f"![{p.stem}]({image(p, f'{name}-{p.name}')})\n" for p in pngs]
        else:
            lines += [f"*Not generated yet: run `make {name}`.*", ""]
    # as the docs site writes them: a negative number with "−", the stars of a formula shown, not read as emphasis
    return formula_stars(typographic_minus("\n".join(lines))) + "\n"


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#1a1a1a;line-height:1.45}
h1{border-bottom:2px solid #333;padding-bottom:.2em} h2{margin-top:2em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:1em 0;font-size:.92em} th,td{border:1px solid #ccc;padding:.3em .6em;
vertical-align:top} th{background:#f3f3f3} span.ok{background:#e6f4e6} span.bad{background:#fbe4e4}
span.meh{background:#fff6d8} img{max-width:100%;border:1px solid #ddd}
pre{background:#f7f7f7;padding:.6em;overflow-x:auto}
"""


_EQ_HEADING = re.compile(r"^###\s+\(([A-Z]?\d+)\).*\{#([\w-]+)\}\s*$", re.M)
_EQ_REF = re.compile(r"\((eqn?:[\w-]+)\)")
_CODE_HTML = re.compile(r"(<pre\b.*?</pre>|<code\b.*?</code>)", re.S)


def equation_numbers(root: Path) -> dict[str, str]:
    """equation_numbers(studies root) -> {'eqn:surv_prob_model': '18', …}: the paper's equation labels and their
    numbers, from the ``### (N) … {#eqn-…}`` headings of the repository's docs/equations.md (empty without it), as
    the docs site numbers them.

    Examples
    --------
    >>> from pathlib import Path
    >>> equation_numbers(Path("/nonexistent/studies"))
    {}
    """
    path = Path(root).parent / "docs" / "equations.md"
    if not path.is_file():
        return {}
    return {anchor.replace("-", ":", 1): num for num, anchor in _EQ_HEADING.findall(path.read_text())}


def number_equations(html_text: str, numbers: dict) -> str:
    """number_equations(html, {label: number}) -> the equation labels "(eqn:…)" written as the site writes them,
    "(18)", outside code; a label without a number stays as written.

    Examples
    --------
    >>> number_equations("Eq. (eqn:surv_prob_model), <code>(eqn:surv_prob_model)</code>", {"eqn:surv_prob_model": "18"})
    'Eq. (18), <code>(eqn:surv_prob_model)</code>'
    """
    parts = _CODE_HTML.split(html_text)
    for i in range(0, len(parts), 2):  # even indices: outside code
        parts[i] = _EQ_REF.sub(lambda m: f"({numbers[m.group(1)]})" if m.group(1) in numbers else m.group(0), parts[i])
    return "".join(parts)


def scripts_outside_code(html_text: str) -> str:
    """scripts_outside_code(html) -> ``e^{−μγt}`` as ``e<sup>−μγt</sup>`` and ``μ_c^{E1}`` alike outside code, as the
    docs site sets them (:func:`hhscatter.publish.formatting.scripts_to_html`).

    Examples
    --------
    >>> scripts_outside_code("E0 e^{−μγt} <code>x^{2}</code>")
    'E0 e<sup>−μγt</sup> <code>x^{2}</code>'
    """
    parts = _CODE_HTML.split(html_text)
    for i in range(0, len(parts), 2):
        parts[i] = scripts_to_html(parts[i])
    return "".join(parts)


def render_html(sections, scale, root) -> str:
    """render_html(sections, scale, root) -> one self-contained HTML page: the report's Markdown (figures as
    data URIs) rendered by Python-Markdown; the paper's equation labels numbered and ``^{…}``/``_{…}`` set as
    superscripts and subscripts, as on the docs site."""
    body = markdown_to_html(
        render_markdown(sections, scale, root, lambda path, name: _img_uri(path), html_verdicts=True)
    )
    body = scripts_outside_code(number_equations(body, equation_numbers(root)))
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>hhscatter reproduction report "
        f"({html.escape(scale)})</title><style>{_CSS}</style></head><body>\n{body}\n</body></html>\n"
    )


def build_report(scale: str = "quick", out: Path | None = None, root: Path | None = None) -> dict:
    """build_report(scale='quick', out=None, root=None) -> {'html', 'markdown', 'missing', 'rows'}.

    Writes ``<out>/report.html`` (self-contained) and ``<out>/report.md`` (+ ``<out>/assets/*.png``);
    ``out`` defaults to ``reports/<scale>``. ``missing`` lists the studies with no figure or numbers.
    """
    root = Path(root) if root is not None else studies_root()
    out = Path(out) if out is not None else root.parent / "reports" / scale
    sections = collect(scale, root)  # verified before anything is written
    assets = out / "assets"
    assets.mkdir(parents=True, exist_ok=True)

    def copy_asset(path: Path, name: str) -> str:
        shutil.copyfile(path, assets / name)
        return f"{assets.name}/{name}"

    md = render_markdown(sections, scale, root, copy_asset)
    page = render_html(sections, scale, root)
    for name, text in (("report.md", md), ("report.html", page)):
        tmp = out / f".{name}.tmp"
        tmp.write_text(text)
        tmp.replace(out / name)
    missing = [s.key for s in sections if s.figure is None or s.numbers is None]
    rows = comparison_rows(sections)
    write_json_atomic(out / "comparison.json", rows)
    return {"html": out / "report.html", "markdown": out / "report.md", "missing": missing, "rows": len(rows)}


def plan_line(scale: str = "quick", root: Path | None = None, cores: int | None = None) -> str:
    """plan_line(scale, root=None, cores=None) -> what ``make report`` at ``scale`` will run before it writes, and
    roughly how long.

    As the Makefile decides: a scale with committed results (other than quick) runs no study; otherwise every
    study without its figure in ``studies/<name>/out/<scale>/`` is run. The time is the CPU time of the committed cost records of that scale
    (``docs/studies/assets[/<scale>]/<study>.cost.json``) over the cores; a study without a record is named. The
    benchmarks whose summaries are missing run too (not timed). An unknown ``scale`` raises
    :class:`~hhscatter.errors.StudyError`.
    """
    root = _checked_root(root, scale)
    cores = cores or os.cpu_count() or 1
    head = f"make report (SCALE={scale})"
    committed = scale != "quick" and any(committed_assets(root, scale).glob("*.json"))
    if committed:
        absent = [i.name for i in study_folders(root) if None in _study_files(root, i.name, scale)[:2]]
        return (
            f"{head}: reads the committed {scale}-scale results and runs no study"
            + (f" (no outputs for {', '.join(absent)}: the report lists them as missing)" if absent else "")
            + "; then the benchmarks whose summaries are missing, then writes."
        )
    missing, cpu, unknown = [], 0.0, []
    for info in study_folders(root):
        if (root / info.name / "out" / scale / f"{info.name}.png").is_file():
            continue
        missing.append(info.name)
        rec = committed_assets(root, scale) / f"{info.name}.cost.json"
        if rec.is_file():
            cpu += sum(t["cpu_s"] for t in totals(json.loads(rec.read_text())).values())
        else:
            unknown.append(info.name)
    if not missing:
        return (
            f"{head}: every study's outputs are there; it runs the benchmarks whose summaries are missing, then writes."
        )
    timed = []
    if len(unknown) < len(missing):
        timed.append(
            f"about {max(1, round(cpu / 60.0 / cores))} min on {cores} core{'s' * (cores > 1)} by the committed cost records"
        )
    if unknown:
        timed.append(f"no cost record for {', '.join(unknown)} (its time is not known here)")
    n = len(missing)
    out = f"{head}: runs {n} stud{'y' if n == 1 else 'ies'} first ({', '.join(missing)}): {'; '.join(timed)}; "
    out += "then the benchmarks whose summaries are missing, then writes."
    if scale == "quick":
        out += " SCALE=paper reads the committed paper-scale results instead."
    return out


def main(argv=None) -> int:

    p = argparse.ArgumentParser(prog="python -m hhscatter.publish.report", description=__doc__.splitlines()[0])
    p.add_argument("--scale", default="quick")
    p.add_argument("--out", help="output folder (default reports/<scale>)")
    p.add_argument(
        "--plan", action="store_true", help="say what the report will run and roughly how long; write nothing"
    )
    a = p.parse_args(argv)
    if a.plan:
        try:
            print(plan_line(a.scale))
        except StudyError as exc:
            print(f"report: error: {exc}", file=sys.stderr)
            return exc.exit_code
        return 0
    try:
        res = build_report(a.scale, a.out)
    except StudyError as exc:
        print(f"report: error: {exc}", file=sys.stderr)
        return exc.exit_code
    print(f"wrote {res['html']} and {res['markdown']} ({res['rows']} comparison rows)")
    if res["missing"]:
        print(f"missing outputs: {', '.join(res['missing'])}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
