"""MkDocs hook: fill generated sections of the pages at build time.

A page asks for generated content with an HTML comment on a line of its own::

    <!-- hh:study-params fig2 -->    studies/fig2/study.toml, verbatim
    <!-- hh:study-figure fig2 -->    docs/studies/assets/fig2.png
    <!-- hh:study-numbers fig2 -->   docs/studies/assets/fig2.json as tables
    <!-- hh:study-module fig2 -->    API of hhscatter.studies.fig2 (if it exists)
    <!-- hh:comparison-all -->       every study's paper-vs-ours rows in one table
    <!-- hh:bench stress -->         docs/benchmarks/assets/stress/*summary.md (+ figures)
    <!-- hh:cli -->                  every subcommand and flag of `hhscatter`
    <!-- hh:schemas -->              the Parquet schemas of hhscatter.tables

Everything is read from files in the repository (no study is run, nothing is
fetched), so the build works offline from a fresh clone. A missing asset gives
a visible "not yet generated" note instead of a broken link, so the strict
build still passes; `make docs-assets` (docs/gen_studies.py) refreshes the
assets from the studies' quick-scale outputs.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

_MARKER = re.compile(r"^<!--\s*hh:([a-z-]+)(?:\s+([\w.-]+))?\s*-->\s*$", re.M)
_SKIP_KEYS = {"study", "scale", "paper_comparison", "config", "provenance"}


# -- number formatting --------------------------------------------------------
def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def fmt_num(v, sig: int = 4) -> str:
    """fmt_num(v) -> v with ``sig`` significant digits (plain or scientific)."""
    if v is None:
        return "—"
    if isinstance(v, str):
        return v
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, int):
        return str(v)
    if not math.isfinite(v):
        return str(v)
    if v == 0:
        return "0"
    a = abs(v)
    if 1e-3 <= a < 1e5:
        return f"{v:.{sig}g}"
    m, e = f"{v:.{sig - 1}e}".split("e")
    return f"{m}×10<sup>{int(e)}</sup>"


def fmt_err(v, err) -> str:
    """fmt_err(v, err) -> "v ± err" with err to 2 significant digits and v to the same decimal place."""
    if not _is_num(v):
        return fmt_num(v)
    if not _is_num(err) or not math.isfinite(err) or err <= 0 or not math.isfinite(v):
        return fmt_num(v) + ("" if err is None else f" ± {fmt_num(err)}")
    exp = math.floor(math.log10(err)) - 1  # last digit kept: 2 significant digits of err
    if -6 <= exp <= 4 and abs(v) < 1e6:
        nd = max(0, -exp)
        return f"{round(v, nd):.{nd}f} ± {round(err, nd):.{nd}f}"
    return f"{fmt_num(v)} ± {fmt_num(err, 2)}"


def fmt_value(v) -> str:
    """fmt_value(v) -> Markdown for one JSON value ({value, err} or {value, lo, hi} dicts, short lists, scalars)."""
    if isinstance(v, dict) and "value" in v:
        if v.get("value") is None:
            return "—"
        if _is_num(v.get("lo")) and _is_num(v.get("hi")):
            return f"{fmt_num(v['value'])} [{fmt_num(v['lo'])}, {fmt_num(v['hi'])}]"
        return fmt_err(v.get("value"), v.get("err"))
    if isinstance(v, list):
        if len(v) <= 8 and all(_is_num(x) or isinstance(x, str) or x is None for x in v):
            return "[" + ", ".join(fmt_num(x) for x in v) + "]"
        if len(v) <= 8 and all(isinstance(x, dict) and "value" in x for x in v):
            return "[" + ", ".join(fmt_value(x) for x in v) + "]"
        if len(v) <= 4 and all(isinstance(x, list) and len(x) <= 4 for x in v):
            return "[" + ", ".join(fmt_value(x) for x in v) + "]"
        return f"*({len(v)} entries; see the JSON)*"
    if isinstance(v, dict):
        return f"*({len(v)} fields; see the JSON)*"
    return fmt_num(v)


def _cell(s) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ")


# -- renderers -----------------------------------------------------------------
class Renderer:
    """Render the markers of one page; ``root`` is the repository, ``docs`` the docs folder."""

    def __init__(self, root: Path, docs: Path, page_dir: Path):
        self.root = root
        self.docs = docs
        self.page_dir = page_dir  # folder of the page's source, relative links start here

    def _rel(self, path: Path) -> str:
        import os

        return Path(os.path.relpath(path, self.page_dir)).as_posix()

    @staticmethod
    def missing(what: str, how: str) -> str:
        return f'!!! warning "Not yet generated"\n    {what} is not in the docs yet. {how}\n'

    def study_asset(self, name: str, ext: str) -> Path:
        return self.docs / "studies" / "assets" / f"{name}.{ext}"

    def study_params(self, name: str) -> str:
        toml = self.root / "studies" / name / "study.toml"
        if not toml.exists():
            return self.missing(f"`studies/{name}/study.toml`", "The study has not been added to the repository.")
        text = toml.read_text().rstrip("\n")
        return (
            f"The study's parameters, verbatim from `studies/{name}/study.toml` "
            "(`[scale.<s>.…]` tables override the quick defaults at `SCALE=<s>`):\n\n"
            f'```toml title="studies/{name}/study.toml"\n{text}\n```\n'
        )

    def study_figure(self, name: str) -> str:
        png = self.study_asset(name, "png")
        if not png.exists():
            return self.missing(
                f"The figure `{name}.png`",
                f"Run `make {name}` and then `make docs-assets` to copy the quick-scale figure here.",
            )
        scale = self._scale_of(name)
        cap = f"`make {name}`" + (f" at scale *{scale}*" if scale else "")
        src = self._rel(png)
        return f"[![{name}: figure made by {cap}]({src})]({src})\n\n*Figure made by {cap} (click for full size).*\n"

    def _numbers(self, name: str):
        path = self.study_asset(name, "json")
        if not path.exists():
            return None
        return json.loads(path.read_text())

    def _scale_of(self, name: str):
        doc = self._numbers(name)
        return doc.get("scale") if doc else None

    def study_numbers(self, name: str) -> str:
        doc = self._numbers(name)
        if doc is None:
            return self.missing(
                f"The numbers `{name}.json`",
                f"Run `make {name}` and then `make docs-assets` to copy the quick-scale numbers here.",
            )
        out = []
        rows = doc.get("paper_comparison") or []
        if rows:
            out.append("Against the paper (± is 1σ of our estimate; the paper gives no uncertainties):\n")
            out.append(comparison_table(rows))
        leaves = []
        for key, v in doc.items():
            if key not in _SKIP_KEYS:
                leaves.extend(_flatten(key, v))
        texts = [(k, v) for k, v in leaves if isinstance(v, str) and len(v) > 40]
        tables = [(k, v) for k, v in leaves if _is_record_list(v)]
        scalars = [(k, v) for k, v in leaves if (k, v) not in texts and (k, v) not in tables]
        if texts:
            out.append("Rules and definitions the study states:\n")
            out.extend(f"`{k}`\n:   {v}\n" for k, v in texts)
        body = []
        for k, recs in tables:
            body.append(f"`{k}`:\n")
            body.append(record_table(recs))
        if scalars:
            body.append("| quantity | value |\n|---|---|")
            body.extend(f"| `{_cell(k)}` | {_cell(fmt_value(v))} |" for k, v in scalars)
            body.append("")
        if body:
            inner = "\n".join(body)
            out.append('??? info "All numbers the study wrote"\n\n' + _indent(inner) + "\n")
        prov = doc.get("provenance") or {}
        bits = [f"scale **{doc.get('scale', '?')}**"]
        bits += [f"{k} {v}" for k, v in prov.items() if v and k != "git_commit"]
        if prov.get("git_commit"):
            bits.append(f"commit `{str(prov['git_commit'])[:12]}`")
        link = self._rel(self.study_asset(name, "json"))
        out.append(f"*Numbers made at {', '.join(bits)}. The full record, with the configuration: [{name}.json]({link}).*\n")
        return "\n".join(out)

    def study_module(self, name: str) -> str:
        mod = self.root / "hhscatter" / "studies" / f"{name}.py"
        if not mod.exists():
            return self.missing(f"The module `hhscatter.studies.{name}`", "It has not been added yet.")
        return (
            f"::: hhscatter.studies.{name}\n"
            "    options:\n"
            "      show_root_heading: false\n"
            "      show_root_toc_entry: false\n"
            "      heading_level: 3\n"
        )

    def comparison_all(self, _arg=None) -> str:
        from hhscatter.studies import STUDY_NAMES

        out, missing = [], []
        for name in STUDY_NAMES:
            doc = self._numbers(name)
            rows = (doc or {}).get("paper_comparison") or []
            if doc is None:
                missing.append(name)
                continue
            for r in rows:
                out.append({**r, "quantity": f"[{name}]({name}.md): {r.get('quantity', '')}"})
        text = comparison_table(out) if out else "*No study has written paper-vs-ours rows yet.*\n"
        if missing:
            text += "\n*Not yet generated: " + ", ".join(f"[{m}]({m}.md)" for m in missing) + ".*\n"
        return text

    def bench(self, which=None) -> str:
        which = which or "bench"
        assets = self.docs / "benchmarks" / "assets" / which
        summaries = sorted(assets.glob("*summary.md")) if assets.exists() else []
        if not summaries:
            return self.missing(
                f"The {which} summary",
                f"Run `make {'bench-engine' if which == 'engine' else which}` and then `make docs-assets` "
                f"to copy `studies/{which}/out/` here.",
            )
        text = "\n\n".join(_embed_markdown(s.read_text(), assets, self._rel) for s in summaries)
        # figures that no summary shows as an image are appended
        for png in sorted(assets.glob("*.png")):
            if f"]({self._rel(png)})" not in text:
                text += f"\n\n![{png.stem}]({self._rel(png)})\n\n*{png.name}*\n"
        return text

    def cli(self, _arg=None) -> str:
        from hhscatter.cli import build_parser

        return cli_reference(build_parser())

    def schemas(self, _arg=None) -> str:
        from hhscatter.tables import _schemas

        out = []
        for name, schema in _schemas().items():
            out.append(f"**`{name}`**\n\n| column | Arrow type |\n|---|---|")
            out.extend(f"| `{f.name}` | `{f.type}`{'' if f.nullable else ' (not null)'} |" for f in schema)
            out.append("")
        return '??? abstract "The Arrow schemas, as the code defines them"\n\n' + _indent("\n".join(out)) + "\n"


def _flatten(key, v, depth=0):
    """(dotted key, value) rows of a numbers JSON entry, down to {value, ...} leaves."""
    if isinstance(v, dict) and "value" not in v and v and depth < 4 and len(v) <= 60:
        rows = []
        for k, x in v.items():
            rows.extend(_flatten(f"{key}.{k}", x, depth + 1))
        return rows
    return [(key, v)]


def _is_record_list(v) -> bool:
    """A list of flat dicts (one row per item, e.g. one per γ) that reads best as a table."""
    return (
        isinstance(v, list)
        and 1 <= len(v) <= 100
        and all(isinstance(x, dict) and "value" not in x for x in v)
        and all(not isinstance(y, (dict, list)) or (isinstance(y, dict) and "value" in y)
                or (isinstance(y, list) and len(y) <= 4) for x in v for y in x.values())
    )


def record_table(recs) -> str:
    """Markdown table of a list of flat dicts; columns are the union of their keys."""
    cols = []
    for r in recs:
        cols.extend(k for k in r if k not in cols)
    out = ["| " + " | ".join(f"`{_cell(c)}`" for c in cols) + " |", "|" + "---|" * len(cols)]
    out.extend("| " + " | ".join(_cell(fmt_value(r.get(c))) for c in cols) + " |" for r in recs)
    return "\n".join(out) + "\n"


def _indent(text: str, n: int = 4) -> str:
    return "\n".join((" " * n + line) if line.strip() else "" for line in text.splitlines())


def comparison_table(rows) -> str:
    """Markdown table of paper-vs-ours rows {quantity, ours, err, paper, unit, verdict, note}."""
    out = ["| quantity | ours | paper | verdict | note |", "|---|---|---|---|---|"]
    for r in rows:
        unit = f" {r['unit']}" if r.get("unit") else ""
        ours = fmt_err(r.get("ours"), r.get("err")) if _is_num(r.get("ours")) else fmt_value(r.get("ours"))
        paper = fmt_value(r.get("paper"))
        out.append(
            f"| {_cell(r.get('quantity', ''))} | {_cell(ours + unit)} | {_cell(paper)} | "
            f"{_cell(r.get('verdict') or '—')} | {_cell(r.get('note') or '')} |"
        )
    return "\n".join(out) + "\n"


def _fix_table_row(line: str) -> str:
    """Escape the bars of |x| inside a table row: a cell separator has spaces (or the line end) on both sides."""
    if re.match(r"^\|[\s:|-]+\|\s*$", line):  # the header separator |---|---|
        return line
    out = []
    for i, ch in enumerate(line):
        if ch == "|" and 0 < i < len(line.rstrip()) - 1 and (line[i - 1] == "\\" or not (
                line[i - 1] == " " and line[i + 1] == " ")):
            out.append(ch if line[i - 1] == "\\" else "\\|")
        else:
            out.append(ch)
    return "".join(out)


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


def _embed_markdown(text: str, assets: Path, rel) -> str:
    """A summary written for its own folder, embedded in a page: headings demoted, links re-based,
    ``|x|`` inside table cells escaped, plain-text tables fenced."""
    text = _fence_plain_tables(text)
    text = "\n".join(_fix_table_row(ln) if ln.startswith("|") else ln for ln in text.split("\n"))
    text = re.sub(r"^(#{1,4}) ", lambda m: "#" * (len(m.group(1)) + 2) + " ", text, flags=re.M)

    def link(m):
        label, target = m.group(1), m.group(2)
        if re.match(r"^[a-z]+:|^#|^/", target):
            return m.group(0)
        local = assets / Path(target).name
        if local.exists():
            return f"{label}({rel(local)})"
        return label.lstrip("!").strip("[]")  # target not copied: keep the text only

    return re.sub(r"(!?\[[^\]]*\])\(([^)\s]+)\)", link, text)


def cli_reference(parser) -> str:
    """Markdown for every subcommand of an argparse parser: usage, description, a table of arguments."""
    import argparse

    out = []
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {c.dest: c.help for c in sub._choices_actions}
    for name, p in sub.choices.items():
        out.append(f"## `hhscatter {name}`\n")
        desc = p.description or helps.get(name) or ""
        if desc:
            out.append(desc.strip() + "\n")
        usage = p.format_usage().replace("usage: ", "", 1).strip()
        out.append(f"```text\n{usage}\n```\n")
        out.append("| argument | meaning |\n|---|---|")
        for a in p._actions:
            if isinstance(a, argparse._HelpAction):
                continue
            if a.option_strings:
                flag = ", ".join(a.option_strings)
                if a.nargs != 0:
                    metavar = a.metavar or (
                        "{" + ",".join(map(str, a.choices)) + "}" if a.choices else a.dest.upper()
                    )
                    if a.nargs in ("*", "+"):
                        metavar += " …"
                    flag += f" {metavar}"
            else:
                flag = a.metavar or a.dest
                if a.choices:
                    flag += " {" + ",".join(map(str, a.choices)) + "}"
                if a.nargs == "?":
                    flag = f"[{flag}]"
                elif a.nargs in ("*", "+"):
                    flag += " …"
            h = (a.help or "").replace("%(default)s", str(a.default))
            if a.required:
                h += " **(required)**"
            out.append(f"| `{_cell(flag)}` | {_cell(h)} |")
        out.append("")
    return "\n".join(out)


# -- MkDocs entry point --------------------------------------------------------
def on_page_markdown(markdown, page, config, files, **kwargs):
    """Replace every ``<!-- hh:... -->`` marker of a page with its generated Markdown."""
    if "<!-- hh:" not in markdown:
        return markdown
    docs = Path(config["docs_dir"])
    root = Path(config["config_file_path"]).resolve().parent
    page_dir = (docs / page.file.src_uri).parent
    r = Renderer(root, docs, page_dir)

    def sub(m):
        kind, arg = m.group(1), m.group(2)
        fn = getattr(r, kind.replace("-", "_"), None)
        if fn is None:
            raise ValueError(f"{page.file.src_uri}: unknown docs marker hh:{kind}")
        return fn(arg)

    return _MARKER.sub(sub, markdown)
