"""Reproduction report: every figure and number of the paper beside ours.

``build_report(scale='quick', out=None)`` reads what the studies left on disk
(``studies/<name>/out/<scale>/<name>.json`` and ``<name>.png``; the benchmark
summary under ``studies/bench/out/``) and writes one self-contained HTML file
(figures embedded as data URIs) and the same content as Markdown beside its
PNG files. It computes no physics: every number comes from a study's numbers
JSON, so the report and the study outputs cannot disagree.
"""
from __future__ import annotations

import base64
import datetime as _dt
import html
import json
import math
import shutil
from dataclasses import dataclass
from pathlib import Path

from .studies import studies_root, write_json_atomic
from .studies.graph import studies as study_folders


@dataclass
class Section:
    key: str
    title: str
    caption: str
    figure: Path | None
    numbers: dict | None
    paper: str = ""  # the paper's figure this study reproduces ("" for a study beyond the paper)


def _fmt(v, err=None) -> str:
    if v is None:
        return "—"
    if isinstance(v, dict) and "value" in v:
        return _fmt(v["value"], v.get("err"))
    if isinstance(v, (bool, int)) and err is None:
        return str(v)
    if isinstance(v, (int, float)):
        if isinstance(v, float) and not math.isfinite(v):
            return str(v)
        if err is None or not isinstance(err, (int, float)) or not math.isfinite(err) or err <= 0:
            return f"{v:.4g}"
        # one significant digit of the error, two when it starts with 1 or 2 (as particle-data tables do)
        exp10 = int(math.floor(math.log10(err)))
        digits = max(0, -exp10 + (1 if err / 10.0**exp10 < 3 else 0))
        if abs(v) >= 1e4 or digits > 5:
            return f"{v:.3g} ± {err:.1e}" if v != 0 else f"0 ± {err:.1e}"
        return f"{v:.{digits}f} ± {err:.{digits}f}"
    if isinstance(v, (list, tuple)):
        if len(v) <= 6 and all(isinstance(x, (int, float)) for x in v):
            return "[" + ", ".join(_fmt(x) for x in v) + "]"
        return f"[{len(v)} values]"
    return str(v)


def headline_numbers(numbers: dict, limit: int = 40) -> list[tuple[str, str]]:
    """headline_numbers(numbers) -> [(name, formatted)] of the scalar and value±err entries of a numbers JSON."""
    skip = {"study", "scale", "paper_comparison", "config", "provenance"}
    rows = []

    def walk(prefix, d, depth):
        for k, v in d.items():
            if k in skip or len(rows) >= limit:
                continue
            name = f"{prefix}{k}"
            if isinstance(v, dict) and "value" in v:
                rows.append((name, _fmt(v)))
            elif isinstance(v, (int, float, bool)) or (isinstance(v, str) and len(v) < 80):
                rows.append((name, _fmt(v)))
            elif isinstance(v, dict) and depth < 1:
                walk(f"{name}.", v, depth + 1)

    walk("", numbers, 0)
    return rows


def collect(scale: str = "quick", root: Path | None = None) -> list[Section]:
    """collect(scale, root=None) -> [Section], one per study folder of ``root`` (in dependency order).

    Titles and captions come from each study's ``[about]`` table; a study
    with ``paper = ""`` goes to the part beyond the paper.
    """
    root = Path(root) if root is not None else studies_root()
    sections = []
    for info in study_folders(root):
        out = root / info.name / "out" / scale
        fig, nums = out / f"{info.name}.png", out / f"{info.name}.json"
        sections.append(Section(info.name, info.title, info.summary, fig if fig.exists() else None,
                                json.loads(nums.read_text()) if nums.exists() else None, info.paper))
    return sections


def comparison_rows(sections) -> list[dict]:
    rows = []
    for s in sections:
        for r in (s.numbers or {}).get("paper_comparison", []):
            rows.append({"study": s.key, **r})
    return rows


def _verdict_class(v):
    if not v:
        return ""
    v = v.lower()
    if v.startswith("agree") or v.startswith("consistent") or v.startswith("reproduced"):
        return "ok"
    if v.startswith("differ") or v.startswith("not"):
        return "bad"
    return "meh"


def _img_uri(path: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(path.read_bytes()).decode()


def _provenance(sections):
    for s in sections:
        if s.numbers and "provenance" in s.numbers:
            return s.numbers["provenance"]
    return {}


BENCH_PARTS = (("bench", "Work–precision and throughput (`make bench`)"),
               ("stress", "Numerical stress tests (`make stress`)"))


def _bench(root: Path, name: str = "bench"):
    """_bench(root, name) -> (summary.md or None, [png]) of the full-scale benchmark/stress output."""
    out = root / name / "out" / "full"
    md = out / "summary.md"
    return (md if md.exists() else None), (sorted(out.glob("*.png")) if out.exists() else [])


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
        counts[_verdict_class(r.get("verdict"))] += 1
    return counts


def _md_rows(rows):
    out = ["| study | quantity | paper | ours | verdict | note |", "|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['study']} | {r['quantity']} | {_fmt(r.get('paper'))} | {_fmt(r.get('ours'), r.get('err'))}"
                   f" | {r.get('verdict') or '—'} | {(r.get('note') or '').replace('|', '/')} |")
    if not rows:
        out.append("| — | no study outputs found | | | | |")
    return out


def _count_line(rows):
    c = verdict_counts(rows)
    return f"{len(rows)} numbers: {c['ok']} agree, {c['bad']} differ, {c['meh'] + c['']} qualitative or not comparable."


def render_markdown(sections, scale, root, assets: Path) -> str:
    paper_rows, beyond_rows = split_rows(comparison_rows(sections), sections)
    prov = _provenance(sections)
    lines = [f"# hhscatter reproduction report ({scale} scale)", "",
             "Reproduction of Burton, Dullin & Altmann, *Dissipative chaotic scattering* (Hénon–Heiles with linear "
             "drag), with exact event times from heyoka's Taylor integrator. Every number below is read from the "
             "studies' numbers JSON files; see `make help` for the targets that made them. Verdicts: |ours − paper| "
             "≤ 2σ (our statistical error) unless the row says otherwise.", "",
             f"Generated {_dt.datetime.now(_dt.timezone.utc):%Y-%m-%d %H:%M UTC}; "
             f"versions: {', '.join(f'{k} {v}' for k, v in prov.items() if isinstance(v, str))}.", "",
             "## The paper's numbers beside ours", "", _count_line(paper_rows), "", *_md_rows(paper_rows), "",
             "## Beyond the paper: checks and numbers the paper does not state", "", _count_line(beyond_rows), "",
             *_md_rows(beyond_rows)]
    for group, of_paper in (("Figures of the paper", True), ("Beyond the paper", False)):
        lines += ["", f"## {group}", ""]
        for s in (s for s in sections if bool(s.paper) == of_paper):
            lines += [f"### {s.title} (`make {s.key}`)", "", s.caption, ""]
            if s.figure:
                shutil.copyfile(s.figure, assets / f"{s.key}.png")
                lines += [f"![{s.title}]({assets.name}/{s.key}.png)", ""]
            else:
                lines += [f"*Not generated yet: run `make {s.key} SCALE={scale}`.*", ""]
            if s.numbers:
                lines += ["| number | value |", "|---|---|"]
                lines += [f"| {k} | {v} |" for k, v in headline_numbers(s.numbers)]
                lines.append("")
    for name, title in BENCH_PARTS:
        md, pngs = _bench(root, name)
        lines += [f"## {title}", ""]
        if md:
            lines += [md.read_text(), ""]
            for p in pngs:
                shutil.copyfile(p, assets / f"{name}-{p.name}")
                lines += [f"![{p.stem}]({assets.name}/{name}-{p.name})", ""]
        else:
            lines += [f"*Not generated yet: run `make {name}`.*", ""]
    return "\n".join(lines) + "\n"


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#1a1a1a;line-height:1.45}
h1{border-bottom:2px solid #333;padding-bottom:.2em} h2{margin-top:2em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:1em 0;font-size:.92em} th,td{border:1px solid #ccc;padding:.3em .6em;
vertical-align:top} th{background:#f3f3f3} td.ok{background:#e6f4e6} td.bad{background:#fbe4e4}
td.meh{background:#fff6d8} img{max-width:100%;border:1px solid #ddd} .caption{color:#444;font-style:italic}
pre{background:#f7f7f7;padding:.6em;overflow-x:auto} .missing{color:#a00}
"""


def _md_table_to_html(text: str) -> str:
    """The benchmark summary is Markdown; render its tables and paragraphs minimally (no extra dependency)."""
    out, table = [], []

    def flush():
        if table:
            cells = [[c.strip() for c in r.strip().strip("|").split("|")] for r in table]
            head, body = cells[0], [r for r in cells[2:]]
            out.append("<table><tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in head) + "</tr>" +
                       "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in body)
                       + "</table>")
            table.clear()

    for line in text.splitlines():
        if line.strip().startswith("|"):
            table.append(line)
            continue
        flush()
        if line.startswith("#"):
            level = min(len(line) - len(line.lstrip("#")) + 2, 6)
            out.append(f"<h{level}>{html.escape(line.lstrip('#').strip())}</h{level}>")
        elif line.strip():
            out.append(f"<p>{html.escape(line)}</p>")
    flush()
    return "\n".join(out)


def _html_rows(rows):
    e = html.escape
    parts = ["<table><tr><th>study</th><th>quantity</th><th>paper</th><th>ours</th><th>verdict</th><th>note</th></tr>"]
    for r in rows:
        parts.append(f"<tr><td>{e(r['study'])}</td><td>{e(str(r['quantity']))}</td><td>{e(_fmt(r.get('paper')))}</td>"
                     f"<td>{e(_fmt(r.get('ours'), r.get('err')))}</td>"
                     f"<td class='{_verdict_class(r.get('verdict'))}'>{e(r.get('verdict') or '—')}</td>"
                     f"<td>{e(r.get('note') or '')}</td></tr>")
    if not rows:
        parts.append("<tr><td colspan=6 class='missing'>no study outputs found</td></tr>")
    parts.append("</table>")
    return "".join(parts)


def render_html(sections, scale, root) -> str:
    paper_rows, beyond_rows = split_rows(comparison_rows(sections), sections)
    prov = _provenance(sections)
    e = html.escape
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>hhscatter reproduction report ({e(scale)})"
             f"</title><style>{_CSS}</style></head><body>",
             f"<h1>hhscatter reproduction report <small>({e(scale)} scale)</small></h1>",
             "<p>Reproduction of Burton, Dullin &amp; Altmann, <i>Dissipative chaotic scattering</i> (Hénon–Heiles "
             "with linear drag), with exact event times from heyoka's Taylor integrator. Every number below is read "
             "from the studies' numbers JSON files. Verdicts: |ours − paper| ≤ 2σ (our statistical error) unless "
             "the row says otherwise.</p>",
             f"<p>Generated {_dt.datetime.now(_dt.timezone.utc):%Y-%m-%d %H:%M UTC}; versions: "
             f"{e(', '.join(f'{k} {v}' for k, v in prov.items() if isinstance(v, str)))}.</p>",
             "<h2>The paper's numbers beside ours</h2>", f"<p>{e(_count_line(paper_rows))}</p>",
             _html_rows(paper_rows),
             "<h2>Beyond the paper: checks and numbers the paper does not state</h2>",
             f"<p>{e(_count_line(beyond_rows))}</p>", _html_rows(beyond_rows)]
    for group, of_paper in (("Figures of the paper", True), ("Beyond the paper", False)):
        parts.append(f"<h2>{e(group)}</h2>")
        for s in (s for s in sections if bool(s.paper) == of_paper):
            parts.append(f"<h3>{e(s.title)} <code>make {e(s.key)}</code></h3><p class='caption'>{e(s.caption)}</p>")
            if s.figure:
                parts.append(f"<img alt='{e(s.title)}' src='{_img_uri(s.figure)}'>")
            else:
                parts.append(f"<p class='missing'>Not generated yet: run <code>make {e(s.key)} SCALE={e(scale)}"
                             f"</code>.</p>")
            if s.numbers:
                parts.append("<table><tr><th>number</th><th>value</th></tr>" + "".join(
                    f"<tr><td>{e(k)}</td><td>{e(v)}</td></tr>" for k, v in headline_numbers(s.numbers)) + "</table>")
    for name, title in BENCH_PARTS:
        md, pngs = _bench(root, name)
        parts.append(f"<h2>{e(title)}</h2>")
        if md:
            parts.append(_md_table_to_html(md.read_text()))
            parts += [f"<img alt='{e(p.stem)}' src='{_img_uri(p)}'>" for p in pngs]
        else:
            parts.append(f"<p class='missing'>Not generated yet: run <code>make {e(name)}</code>.</p>")
    parts.append("</body></html>")
    return "\n".join(parts)


def build_report(scale: str = "quick", out: Path | None = None, root: Path | None = None) -> dict:
    """build_report(scale='quick', out=None, root=None) -> {'html', 'markdown', 'missing', 'rows'}.

    Writes ``<out>/report.html`` (self-contained) and ``<out>/report.md`` (+ ``<out>/assets/*.png``);
    ``out`` defaults to ``reports/<scale>``. ``missing`` lists the studies with no figure or numbers.
    """
    root = Path(root) if root is not None else studies_root()
    out = Path(out) if out is not None else root.parent / "reports" / scale
    assets = out / "assets"
    assets.mkdir(parents=True, exist_ok=True)
    sections = collect(scale, root)
    md = render_markdown(sections, scale, root, assets)
    page = render_html(sections, scale, root)
    for name, text in (("report.md", md), ("report.html", page)):
        tmp = out / f".{name}.tmp"
        tmp.write_text(text)
        tmp.replace(out / name)
    missing = [s.key for s in sections if s.figure is None or s.numbers is None]
    rows = comparison_rows(sections)
    write_json_atomic(out / "comparison.json", rows)
    return {"html": out / "report.html", "markdown": out / "report.md", "missing": missing, "rows": len(rows)}


def main(argv=None) -> int:
    import argparse

    p = argparse.ArgumentParser(prog="python -m hhscatter.report", description=__doc__.splitlines()[0])
    p.add_argument("--scale", default="quick")
    p.add_argument("--out", help="output folder (default reports/<scale>)")
    a = p.parse_args(argv)
    res = build_report(a.scale, a.out)
    print(f"wrote {res['html']} and {res['markdown']} ({res['rows']} comparison rows)")
    if res["missing"]:
        print(f"missing outputs: {', '.join(res['missing'])}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
