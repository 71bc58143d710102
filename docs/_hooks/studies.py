"""MkDocs hook: fill generated sections of the pages at build time.

A page asks for generated content with an HTML comment on a line of its own::

    <!-- hh:study-params fig2 -->    studies/fig2/study.toml, verbatim
    <!-- hh:study-figure fig2 -->    docs/studies/assets/fig2.png
    <!-- hh:study-numbers fig2 -->   docs/studies/assets/fig2.json as tables
    <!-- hh:study-module fig2 -->    API of hhscatter.studies.fig2 (if it exists)
    <!-- hh:claims-table generality -->  its JSON's ``claims`` records as a claims × systems table
    <!-- hh:evidence-tables generality -->  its JSON's regular_fraction, long_time, validity_map, resc records
    <!-- hh:study-figure-wide generality_regular -->  a further figure of a study, as hh:study-figure
                                     (paper scale first when committed, quick scale folded below)
    <!-- hh:comparison-all -->       every study's paper-vs-ours rows in one table
    <!-- hh:studies-table -->        one row per study folder: title, paper figure, summary, what it needs
    <!-- hh:bench stress -->         docs/benchmarks/assets/stress/*summary.md (+ figures)
    <!-- hh:cli -->                  every subcommand and flag of `hhscatter`
    <!-- hh:schemas -->              the Parquet schemas of hhscatter.data.schema

The "Studies" section of the navigation is made from the study folders
(``studies/<name>/study.toml``, table ``[about]``) by ``on_config``: a new
study folder gets its page in the nav without editing mkdocs.yml.

Everything is read from files in the repository (no study is run, nothing is
fetched), so the build works offline from a fresh clone. A missing asset gives
a visible "not yet generated" note instead of a broken link, so the strict
build still passes; `make docs-assets` (docs/gen_studies.py) refreshes the
assets from the studies' quick-scale outputs.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

_MARKER = re.compile(r"^([ \t]*)<!--\s*hh:([a-z-]+)(?:\s+([\w.-]+))?\s*-->[ \t]*$", re.M)
#: the make target that writes a benchmark's summaries, where it is not the benchmark's name
_BENCH_TARGETS = {"engine": "bench-engine", "noise": "bench"}
_SKIP_KEYS = {"study", "scale", "paper_comparison", "config", "provenance", "made_from", "sha256"}


# -- number formatting: hhscatter.publish.formatting, shared with the report and the figures ---------------------
def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def fmt_num(v, sig: int = 4) -> str:
    """fmt_num(v) -> v with ``sig`` significant digits (a×10<sup>b</sup> outside [1e-3, 1e5))."""
    from hhscatter.publish.formatting import format_number

    return format_number(v, sig, html=True)


def fmt_err(v, err) -> str:
    """fmt_err(v, err) -> "v ± err" rounded to the uncertainty (hhscatter.publish.formatting.format_value_err)."""
    from hhscatter.publish.formatting import format_value_err

    return format_value_err(v, err)


def fmt_value(v) -> str:
    """fmt_value(v) -> Markdown for one JSON value ({value, err} or {value, lo, hi} dicts, short lists, scalars)."""
    from hhscatter.publish.formatting import format_value

    return format_value(v, html=True)


def fmt_leaf(key: str, v) -> str:
    """fmt_leaf(key, v) -> Markdown for one JSON leaf by its dotted key (a difference of the reference to itself:
    "reference"; hhscatter.publish.formatting.format_leaf)."""
    from hhscatter.publish.formatting import format_leaf

    return format_leaf(key, v, html=True)


def _cell(s) -> str:
    from hhscatter.publish.formatting import md_cell

    return md_cell(s)


def typographic_minus(text: str) -> str:
    """A negative number's hyphen written "−" (hhscatter.publish.formatting.typographic_minus)."""
    from hhscatter.publish.formatting import typographic_minus as minus

    return minus(text)


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

    def study_asset(self, name: str, ext: str, scale: str = "quick") -> Path:
        from hhscatter.publish.report import committed_assets

        return committed_assets(self.root / "studies", scale) / f"{name}.{ext}"

    def study_params(self, name: str) -> str:
        toml = self.root / "studies" / name / "study.toml"
        if not toml.exists():
            return self.missing(f"`studies/{name}/study.toml`", "The study has not been added to the repository.")
        text = toml.read_text().rstrip("\n")
        out = (
            f"The study's parameters, verbatim from `studies/{name}/study.toml` "
            "(`[scale.<s>.…]` tables override the quick defaults at `SCALE=<s>`):\n\n"
            f'```toml title="studies/{name}/study.toml"\n{text}\n```\n'
        )
        conv = self.root / "studies" / "conventions.toml"
        if conv.exists() and re.search(r"(?m)^convention\s*=", text):
            out += (
                "\nIts `convention` lays these scene keys under its `[scene]`, from the one file that declares "
                "them for every figure study:\n\n"
                f'```toml title="studies/conventions.toml"\n{conv.read_text().rstrip()}\n```\n'
            )
        # folded: the configuration is there for who looks for it, not in the way of the figure (click to open)
        return f'??? abstract "Configuration: `studies/{name}/study.toml` (click to open)"\n\n' + _indent(out) + "\n"

    def study_figure(self, name: str) -> str:
        """The study's figure at the headline scale (paper where committed) at the full width of the text, a click
        zooms it (docs/javascripts/zoom.js); the quick-scale figure folded below it."""
        png = self.study_asset(name, "png")
        paper = self.study_asset(name, "png", "paper")
        from hhscatter.studies.graph import studies

        # the study that draws it: a further figure <study>_<part>.png belongs to the study <study> (a folder with
        # a study.toml, as the graph and docs/gen_studies.py define a study)
        names = {s.name for s in studies(self.root / "studies")}
        parts = name.split("_")
        study = next(("_".join(parts[:i]) for i in range(len(parts), 0, -1) if "_".join(parts[:i]) in names), name)
        if not png.exists() and not paper.exists():
            return self.missing(
                f"The figure `{name}.png`",
                f"Run `make {study}` and then `make docs-assets` to copy the quick-scale figure here.",
            )

        def one(path, alt, caption, cls="hh-figure"):
            src = self._rel(path)
            return (
                f'<figure class="{cls}" markdown="span">\n[![{alt}]({src})]({src}){{ .hh-zoom }}\n'
                f"<figcaption>{caption} (click to zoom)</figcaption>\n</figure>\n"
            )

        def figure(path, scale, cmd):
            """The figure at one scale; a multi-panel figure whose plot stage wrote its panels one by one
            (``<name>_panel_<letter>.png``, hhscatter.publish.figures.save_panels) panel by panel, each at its natural
            width (at most the text's: a panel is never upscaled), the composite folded below them."""
            whole = one(path, f"{name}, {scale} scale", f"{scale.capitalize()} scale: <code>{cmd}</code>")
            panels = sorted(path.parent.glob(f"{path.stem}_panel_*.png"))
            if not panels:
                return whole
            out = "".join(
                one(
                    p,
                    f"{name}, panel ({p.stem[-1]}), {scale} scale",
                    f"({p.stem[-1]}) {scale} scale: <code>{cmd}</code>",
                    "hh-figure hh-panel",  # at its natural width (never upscaled), at most the text's
                )
                for p in panels
            )
            return out + '\n??? note "The panels in one image (click to open)"\n\n' + _indent(whole) + "\n"

        if not paper.exists():
            return figure(png, "quick", f"make {study}")
        out = figure(paper, "paper", f"make {study} SCALE=paper")
        if png.exists():
            out += (
                '\n??? note "The same figure at the quick scale (click to open)"\n\n'
                + _indent(figure(png, "quick", f"make {study}"))
                + "\n"
            )
        return out

    def _numbers(self, name: str, scale: str = "quick"):
        """The committed numbers JSON of study ``name`` at ``scale`` (None if not committed), verified as the
        ``[[study:path]]`` references are: an edited or unsealed file is refused
        (:func:`hhscatter.publish.numbers.read_numbers_file`)."""
        from hhscatter.publish.numbers import read_numbers_file

        path = self.study_asset(name, "json", scale)
        if not path.exists():
            return None
        return read_numbers_file(path)

    def _headline(self, name: str):
        """(numbers JSON, scale) at the headline scale: paper where committed, else quick (None, None if neither)."""
        for scale in ("paper", "quick"):
            doc = self._numbers(name, scale)
            if doc is not None:
                return doc, scale
        return None, None

    def _scale_of(self, name: str):
        doc = self._numbers(name)
        return doc.get("scale") if doc else None

    def _both_scales(self, quick_rows, paper_rows) -> str:
        """The paper-vs-ours rows at both scales in one table, matched by quantity."""
        from hhscatter.publish.formatting import format_value, ours_cell
        from hhscatter.reproduction.verdicts import row_verdict

        def ours(r):
            return "—" if r is None else ours_cell(r)

        q = {r["quantity"]: r for r in quick_rows}
        order = [r["quantity"] for r in paper_rows] + [k for k in q if k not in {r["quantity"] for r in paper_rows}]
        p = {r["quantity"]: r for r in paper_rows}
        out = [
            "| quantity | ours, quick | ours, paper scale | convention (ours) | paper | verdict (paper scale) |",
            "|---|---|---|---|---|---|",
        ]
        for k in order:
            a, b = q.get(k), p.get(k)
            r = b or a
            out.append(
                f"| {_cell(k)} | {_cell(ours(a))} | {_cell(ours(b))} | {_cell(r.get('convention') or '—')} | "
                f"{_cell(format_value(r.get('paper')))} | {_cell(row_verdict(b, 'paper') if b else '—')} |"
            )
        return "\n".join(out) + "\n"

    def study_numbers(self, name: str) -> str:
        """The paper-vs-ours rows (both scales side by side when the paper scale is committed, its verdicts by the one
        rule) and every number the study wrote at the headline scale, folded."""
        doc, scale = self._headline(name)
        if doc is None:
            return self.missing(
                f"The numbers `{name}.json`",
                f"Run `make {name}` and then `make docs-assets` to copy the quick-scale numbers here.",
            )
        out = []
        quick = self._numbers(name, "quick")
        rows = doc.get("paper_comparison") or []
        if scale == "paper" and quick is not None:
            out.append(
                "Against the paper, at both scales (± is 1σ of our estimate; the verdict is the paper "
                "scale's, by the rule of the [studies index](index.md#the-papers-numbers-beside-ours)):\n"
            )
            out.append(self._both_scales(quick.get("paper_comparison") or [], rows))
        elif rows:
            out.append(f"Against the paper, {scale} scale (± is 1σ of our estimate):\n")
            out.append(comparison_table(rows, scale=scale))
        leaves = []
        for key, v in doc.items():
            if key not in _SKIP_KEYS:
                leaves.extend(_flatten(key, v))
        texts = [(k, v) for k, v in leaves if isinstance(v, str) and len(v) > 40]
        tables = [(k, v) for k, v in leaves if _is_record_list(v)]
        scalars = [(k, v) for k, v in leaves if (k, v) not in texts and (k, v) not in tables]
        if texts:
            out.append(
                '??? abstract "Rules and definitions the study states (click to open)"\n\n'
                + _indent("\n".join(f"`{k}`\n:   {v}\n" for k, v in texts))
                + "\n"
            )
        body = []
        for k, recs in tables:
            body.append(f"`{k}`:\n")
            body.append(record_table(recs))
        if scalars:
            body.append("| quantity | value |\n|---|---|")
            body.extend(f"| `{_cell(k)}` | {_cell(fmt_leaf(k, v))} |" for k, v in scalars)
            body.append("")
        if body:
            inner = "\n".join(body)
            out.append(
                f'??? info "All numbers the study wrote, {scale} scale (click to open)"\n\n' + _indent(inner) + "\n"
            )
        prov = doc.get("provenance") or {}
        bits = [f"scale **{doc.get('scale', scale)}**"]
        bits += [f"{k} {v}" for k, v in prov.items() if v and k != "git_commit"]
        if prov.get("git_commit"):
            bits.append(f"commit `{str(prov['git_commit'])[:12]}`")
        link = self._rel(self.study_asset(name, "json", scale))
        more = ""
        if scale == "paper" and quick is not None:
            more = f" The quick scale's: [{name}.json (quick)]({self._rel(self.study_asset(name, 'json'))})."
        out.append(
            f"*Numbers made at {', '.join(bits)}. The full record, with the configuration: "
            f"[{name}.json]({link}).{more}*\n"
        )
        return "\n".join(out)

    def claims_table(self, name: str) -> str:
        """The study's ``claims`` records ({claim, quantity, system, value, err, verdict}) as one table,
        claims × systems: the paper scale's when committed (the quick scale's folded below), else the quick's."""
        docs = {sc: self._numbers(name, sc) for sc in ("paper", "quick")}
        docs = {sc: d for sc, d in docs.items() if d and d.get("claims")}
        if not docs:
            return self.missing(f"The claims of study {name}", f"Run `make {name}`, then `make docs-assets`.")
        out = []
        for i, (sc, doc) in enumerate(docs.items()):
            table = claims_table(doc)
            link = self._rel(self.study_asset(name, "json", sc))
            caption = (
                f"*Scale **{sc}**: the records `claims` of [{name}.json ({sc})]({link}); a cell is "
                f"value ± 1σ: verdict (z = distance to the reference in σ).*\n"
            )
            if i == 0:
                out.append(table + "\n" + caption)
            else:
                out.append(
                    f'??? info "The same table at the {sc} scale (click to open)"\n\n'
                    + _indent(table + "\n" + caption)
                    + "\n"
                )
        return "\n".join(out)

    def evidence_tables(self, name: str) -> str:
        """The evidence records of a numbers JSON (regular fraction, long-time fits, validity map, r_esc) as
        tables, at the headline scale; below a paper-scale headline, the quick scale's folded."""
        doc, sc = self._headline(name)
        if not doc or "regular_fraction" not in doc:
            return self.missing(f"The evidence of study {name}", f"Run `make {name}`, then `make docs-assets`.")
        link = self._rel(self.study_asset(name, "json", sc))
        out = evidence_tables(doc) + f"\n*Scale **{sc}**: records of [{name}.json ({sc})]({link}).*\n"
        quick = self._numbers(name, "quick") if sc == "paper" else None
        if quick and "regular_fraction" in quick:  # the quick scale's evidence, folded below the headline's
            qlink = self._rel(self.study_asset(name, "json"))
            body = evidence_tables(quick) + f"\n*Scale **quick**: records of [{name}.json (quick)]({qlink}).*\n"
            out += '\n??? info "The evidence at the quick scale (click to open)"\n\n' + _indent(body) + "\n"
        return out

    def study_figure_wide(self, name: str) -> str:
        """A further figure of a study (``<study>_<part>.png``) shown as hh:study-figure shows the main one (paper
        scale at full width, quick folded); a marker of its own so that the main figure keeps the page's top."""
        return self.study_figure(name)

    def _scaled_docs(self, name: str, key: str):
        """[(scale, doc)] of the study's committed JSON that hold ``key`` (dotted), paper scale first."""
        out = []
        for sc in ("paper", "quick"):
            doc = self._numbers(name, sc)
            if doc is not None and _dig(doc, key) not in (None, [], {}):
                out.append((sc, doc))
        return out

    def study_table(self, arg: str) -> str:
        """``<!-- hh:study-table name.key -->``: the records at ``key`` of the study's JSON as a table (columns
        from :data:`STUDY_TABLES`; value ± error rounded to the error; a missing value "—"), the paper scale
        first and the quick scale folded below.  ``name.key@view`` shows the same records with the columns of
        the entry ``name.key@view`` (a wide record split into tables that fit the page)."""
        name, key = arg.split("@", 1)[0].split(".", 1)
        docs = self._scaled_docs(name, key)
        if not docs:
            return self.missing(f"`{key}` of {name}.json", f"Run `make {name}`, then `make docs-assets`.")
        out = []
        for i, (sc, doc) in enumerate(docs):
            link = self._rel(self.study_asset(name, "json", sc))
            text = (
                spec_table(_dig(doc, key), STUDY_TABLES.get(arg))
                + f"\n*Scale **{sc}**: `{key}` of [{name}.json ({sc})]({link}).*\n"
            )
            out.append(
                text if i == 0 else f'??? info "The same at the {sc} scale (click to open)"\n\n' + _indent(text) + "\n"
            )
        return "\n".join(out)

    def study_statement(self, arg: str) -> str:
        """``<!-- hh:study-statement name.key -->``: the ``statement`` string at ``key`` of the study's JSON, at
        each committed scale (paper first)."""
        name, key = arg.split(".", 1)
        docs = self._scaled_docs(name, key)
        if not docs:
            return self.missing(f"`{key}` of {name}.json", f"Run `make {name}`, then `make docs-assets`.")
        return "\n".join(f"- *{sc} scale*: {_dig(doc, key)['statement']}." for sc, doc in docs) + "\n"

    def study_module(self, name: str) -> str:
        mod = self.root / "studies" / name / "study.py"
        if not mod.exists():
            return self.missing(f"The module `studies/{name}/study.py`", "It has not been added yet.")
        return (
            f"::: studies.{name}.study\n"
            "    options:\n"
            "      show_root_heading: false\n"
            "      show_root_toc_entry: false\n"
            "      heading_level: 3\n"
        )

    def studies_table(self, _arg=None) -> str:
        from hhscatter.studies.graph import studies

        out = ["| study | paper | what | needs |", "|---|---|---|---|"]
        for s in studies(self.root / "studies"):
            needs = ", ".join(f"[{u}]({u}.md)" for u in s.upstream)
            out.append(
                f"| [{s.name}]({s.name}.md) | {_cell(s.paper or 'beyond the paper')} | {_cell(s.summary)} | {needs} |"
            )
        return "\n".join(out) + "\n"

    def comparison_all(self, _arg=None) -> str:
        """Every study's paper-vs-ours rows in one table, each at its headline scale (paper where committed)."""
        from hhscatter.studies.graph import studies

        out, missing, scales = [], [], {}
        for name in (s.name for s in studies(self.root / "studies")):
            doc, scale = self._headline(name)
            if doc is None:
                missing.append(name)
                continue
            scales.setdefault(scale, []).append(name)
            for r in doc.get("paper_comparison") or []:
                out.append({**r, "scale": scale, "study": name})
        from hhscatter.publish.formatting import comparison_table as table
        from hhscatter.publish.formatting import md_cell

        def linked(r):  # the row keeps its own quantity (its verdict is the row's); the cell links the study
            return md_cell(f"[{r['study']}]({r['study']}.md): {r.get('quantity', '')}")

        text = table(out, quantity=linked) if out else "*No study has written paper-vs-ours rows yet.*\n"
        said = "; ".join(f"{sc} scale: " + ", ".join(f"[{n}]({n}.md)" for n in names) for sc, names in scales.items())
        text += f"\n*Scale of each study's rows — {said}.*\n" if said else ""
        if missing:
            text += "\n*Not yet generated: " + ", ".join(f"[{m}]({m}.md)" for m in missing) + ".*\n"
        return text

    def headline_results(self, _arg=None) -> str:
        """The README's results (tools/readme_results.md), its numbers and verdicts rendered from the committed JSON
        as the README's are: the docs home opens with them."""
        from hhscatter.publish.numbers import render_refs

        text = (self.root / "tools" / "readme_results.md").read_text()
        text = re.sub(r"\A<!--.*?-->\n", "", text, flags=re.S)  # the template's own note
        return render_refs(text, self.root, where="tools/readme_results.md")

    def verdict_rule(self, _arg=None) -> str:
        """The one verdict rule, as the code states it (hhscatter.reproduction.verdicts.RULE)."""
        from hhscatter.reproduction.verdicts import RULE

        return f'!!! info "The verdict rule (every table and page)"\n    {RULE}\n'

    def bench(self, which=None) -> str:
        which = which or "bench"
        assets = self.docs / "benchmarks" / "assets" / which
        summaries = sorted(assets.glob("*summary.md")) if assets.exists() else []
        if not summaries:
            return self.missing(
                f"The {which} summary",
                f"Run `make {_BENCH_TARGETS.get(which, which)}` and then `make docs-assets` "
                f"to copy `studies/{which}/out/` here.",
            )
        from hhscatter.publish.words import in_glossary_words

        # a summary written before the benchmarks used the glossary's words is read in them
        text = "\n\n".join(_embed_markdown(in_glossary_words(s.read_text()), assets, self._rel) for s in summaries)
        # figures that no summary shows as an image are appended
        for png in sorted(assets.glob("*.png")):
            if f"]({self._rel(png)})" not in text:
                text += f"\n\n![{png.stem}]({self._rel(png)})\n\n*{png.name}*\n"
        return text

    def bench_goals(self, _arg=None) -> str:
        """The engine's goals against what was measured (docs/benchmarks/assets/engine/engine.csv, the rows with a
        goal), with a count of the goals met: the first thing the benchmarks page says."""
        import csv

        path = self.docs / "benchmarks" / "assets" / "engine" / "engine.csv"
        if not path.exists():
            return self.missing("The engine's goals", "Run `make bench-engine` and then `make docs-assets`.")
        rows = [r for r in csv.DictReader(path.open()) if (r.get("goal") or "").strip()]
        out = ["| target | measure | goal | measured | met |", "|---|---|---|---|---|"]
        met = 0
        for r in rows:
            ok = goal_met(float(r["value"]), r["goal"])
            met += bool(ok)
            out.append(
                f"| {_cell(r['target'])} | {_cell(r['measure'])} | {_cell(r['goal'])} | "
                f"{fmt_num(float(r['value']), 3)} | {'yes' if ok else '**no**' if ok is False else '?'} |"
            )
        head = (
            f"**{met} of {len(rows)} goals met** (`make bench-engine`, one core, best of three; the "
            "[engine targets](#engine-targets) below give every measurement and its note):\n"
        )
        return head + "\n" + "\n".join(out) + "\n"

    def _costs(self, scale: str) -> dict:
        """{study: hhscatter.studies.cost.summary of its committed cost record at ``scale``}."""
        from hhscatter.studies.cost import summary
        from hhscatter.studies.graph import studies

        out = {}
        for st in studies(self.root / "studies"):
            path = self.study_asset(st.name, "cost.json", scale)
            if path.exists():
                out[st.name] = summary(json.loads(path.read_text()))
        return out

    def cost_table(self, _arg=None) -> str:
        """Per study, quick and paper scale: CPU hours, wall hours, orbits, peak RSS, and the ratios."""
        quick, paper = self._costs("quick"), self._costs("paper")
        names = [n for n in paper] + [n for n in quick if n not in paper]
        if not names:
            return self.missing("The cost records", "Run the studies, then `make docs-assets` (SCALE=quick, paper).")

        def agg(c):
            if not c:
                return None
            return {
                "cpu": c["cpu_s"] / 3600,
                "wall": c["wall_s"] / 3600,
                "orbits": c["orbits"],
                "rss": c["rss_mb"],
                "analysis": c["analysis_cpu_s"] / 3600,
            }

        def f(x, fmt):
            return "—" if x is None else format(x, fmt)

        out = [
            "| study | CPU h (quick → paper) | wall h (quick → paper) | orbits (quick → paper) | ratio of orbits | "
            "ratio of CPU | analysis + plot CPU h (paper) | peak RSS MB (quick → paper) |",
            "|---|---|---|---|---|---|---|---|",
        ]
        tot = {"q": 0.0, "p": 0.0, "qw": 0.0, "pw": 0.0}
        for n in names:
            q, p = agg(quick.get(n)), agg(paper.get(n))
            ro = p["orbits"] / q["orbits"] if p and q and q["orbits"] else None
            rc = p["cpu"] / q["cpu"] if p and q and q["cpu"] else None
            out.append(
                f"| [{n}]({n}.md) | {f(q and q['cpu'], '.3f')} → {f(p and p['cpu'], '.2f')} | "
                f"{f(q and q['wall'], '.3f')} → {f(p and p['wall'], '.2f')} | {f(q and q['orbits'], '.3g')} → "
                f"{f(p and p['orbits'], '.3g')} | {f(ro, '.0f')} | {f(rc, '.0f')} | {f(p and p['analysis'], '.3f')} | "
                f"{f(q and q['rss'], '.0f')} → {f(p and p['rss'], '.0f')} |"
            )
            tot["q"] += q["cpu"] if q else 0.0
            tot["p"] += p["cpu"] if p else 0.0
            tot["qw"] += q["wall"] if q else 0.0
            tot["pw"] += p["wall"] if p else 0.0
        out.append(f"| **total** | **{tot['q']:.2f} → {tot['p']:.2f}** | {tot['qw']:.2f} → {tot['pw']:.2f} | | | | | |")
        return "\n".join(out) + "\n"

    def scale_changes(self, only=None) -> str:
        """Every paper-vs-ours number that moved between quick and paper scale by more than its quick-scale error
        (of one study: ``<!-- hh:scale-changes fig2 -->``, e.g. inside the page's folded quick-vs-paper note)."""
        from hhscatter.studies.graph import studies

        out = ["| study | quantity | quick | paper scale | change / σ_quick |", "|---|---|---|---|---|"]
        n = 0
        for st in studies(self.root / "studies"):
            if only and st.name != only:
                continue
            q, p = self._numbers(st.name), self._numbers(st.name, "paper")
            if not q or not p:
                continue
            qr = {r["quantity"]: r for r in q.get("paper_comparison") or []}
            for r in p.get("paper_comparison") or []:
                a = qr.get(r["quantity"])
                if not a or not (_is_num(a.get("ours")) and _is_num(r.get("ours")) and _is_num(a.get("err"))):
                    continue
                if not a["err"] or abs(r["ours"] - a["ours"]) <= a["err"]:
                    continue
                n += 1
                out.append(
                    f"| [{st.name}]({st.name}.md) | {_cell(r['quantity'])} | {fmt_err(a['ours'], a['err'])} | "
                    f"{fmt_err(r['ours'], r.get('err'))} | {(r['ours'] - a['ours']) / a['err']:+.1f} |"
                )
        if n == 0:
            return "*No paper-scale number differs from its quick-scale value by more than the quick-scale error.*\n"
        return "\n".join(out) + "\n"

    def outcomes(self, _arg=None) -> str:
        """The outcome names and what each means, from hhscatter.outcomes (the one declaration)."""
        import hhscatter.outcomes as oc

        doc = oc.__doc__ or ""
        out = []
        for name in oc.OUTCOMES:
            m = re.search(rf"^\* ``{name}``: (.*?)(?=^\* ``|^\s*$)", doc, flags=re.M | re.S)
            what = " ".join(m.group(1).split()) if m else ""
            censor = " (censors the lifetime)" if name in oc.CENSORING_OUTCOMES else ""
            out.append(f"- `{name}`: {what}{censor}")
        return "\n".join(out) + "\n"

    def study_names(self, _arg=None) -> str:
        """The studies `make studies` builds, from the study folders, in the order it builds them."""
        from hhscatter.studies.graph import studies

        names = [s.name for s in studies(self.root / "studies")]
        links = ", ".join(f"[{n}](studies/{n}.md)" for n in names)
        return f"`make studies` builds {len(names)} studies, one per folder, each after the ones it needs: {links}.\n"

    def cli(self, _arg=None) -> str:
        from hhscatter.cli import build_parser

        return cli_reference(build_parser())

    def schemas(self, _arg=None) -> str:
        from hhscatter.data.schema import _schemas

        out = []
        for name, schema in _schemas().items():
            out.append(f"**`{name}`**\n\n| column | Arrow type |\n|---|---|")
            out.extend(f"| `{f.name}` | `{f.type}`{'' if f.nullable else ' (not null)'} |" for f in schema)
            out.append("")
        return '??? abstract "The Arrow schemas, as the code defines them"\n\n' + _indent("\n".join(out)) + "\n"


def goal_met(value: float, goal: str):
    """goal_met(3.1, "≤ 2 (1.5)") -> False: the first comparison of a goal text ("≤ x", "≥ x", "< x", "> x");
    None when the goal states none."""
    m = re.match(r"\s*(≤|≥|<|>|<=|>=)\s*([-+0-9.eE]+)", goal)
    if not m:
        return None
    op, x = m.group(1), float(m.group(2))
    return {"≤": value <= x, "<=": value <= x, "<": value < x, "≥": value >= x, ">=": value >= x, ">": value > x}[op]


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
        and all(
            not isinstance(y, (dict, list))
            or (isinstance(y, dict) and "value" in y)
            or (isinstance(y, list) and len(y) <= 4)
            for x in v
            for y in x.values()
        )
    )


def claims_table(doc) -> str:
    """Markdown table claims × systems of a numbers JSON with a ``claims`` list and a ``systems`` dict
    ({label: {n_exits, E_c, ...}}); rows by claim, within a claim in the order the records first appear; each
    verdict by the one rule (:func:`hhscatter.reproduction.verdicts.claim_verdict`)."""
    from hhscatter.reproduction.verdicts import claim_verdict

    systems = list((doc.get("systems") or {}).keys())
    for c in doc["claims"]:
        if c.get("system") not in systems:
            systems.append(c.get("system"))
    rows: dict = {}
    for c in doc["claims"]:
        rows.setdefault((str(c.get("claim")), c.get("quantity", "")), {})[c.get("system")] = c

    def head(label):
        info = (doc.get("systems") or {}).get(label) or {}
        bits = [
            f"{info['n_exits']} exits" if info.get("n_exits") is not None else "",
            f"E_c = {fmt_num(info['E_c'], 4)}" if _is_num(info.get("E_c")) else "",
        ]
        bits = [b for b in bits if b]
        return f"{label} ({', '.join(bits)})" if bits else str(label)

    def cell(c):
        if c is None:
            return "—"
        v, e = c.get("value"), c.get("err")
        val = (
            "n/a" if v is None else (fmt_err(v, e) if _is_num(e) else fmt_value(v) if not _is_num(v) else fmt_num(v, 3))
        )
        verdict = claim_verdict(c, doc.get("scale")) if c.get("verdict") else None  # the rule of every table
        return _cell(f"{val}: {verdict}" if verdict else val)

    out = [
        "| claim | quantity | " + " | ".join(_cell(head(s)) for s in systems) + " |",
        "|---|---|" + "---|" * len(systems),
    ]

    def claim_order(item):  # by claim (numbers numerically), then in the order the records first appear
        claim = item[0][0]
        return (0, float(claim), "") if re.fullmatch(r"\d+(\.\d+)?", claim) else (1, 0.0, claim)

    for (claim, qty), per in sorted(rows.items(), key=claim_order):
        out.append(f"| {_cell(claim)} | {_cell(qty)} | " + " | ".join(cell(per.get(s)) for s in systems) + " |")
    return "\n".join(out) + "\n"


def _dig(doc, key: str):
    """The value at the dotted ``key`` of a JSON document (None if absent)."""
    cur = doc
    for part in key.split("."):
        if not isinstance(cur, dict) or part not in cur:
            return None
        cur = cur[part]
    return cur


#: columns (key, header) of the record tables that study pages ask for with ``hh:study-table``; a key with a
#: sibling ``<key>_err`` is shown as value ± error rounded to the error
STUDY_TABLES = {
    "basins.entropy_by_box": (
        ("E0", "E0"),
        ("gamma", "γ"),
        ("map", "map"),
        ("grid", "grid (cells per side)"),
        ("box_side", "box side s"),
        ("box_cells", "box (cells)"),
        ("S_b", "S_b"),
        ("S_bb", "S_bb"),
    ),
    "basins.entropy_by_box_at": (
        ("E0", "E0"),
        ("gamma", "γ"),
        ("box_side", "box side s"),
        ("map", "map"),
        ("grid", "grid (cells per side)"),
        ("box_cells", "box (cells)"),
        ("S_b", "S_b"),
        ("S_bb", "S_bb"),
    ),
    "basins.point_table": (
        ("E0", "E0"),
        ("gamma", "γ"),
        ("d", "d = 2 − α, one law"),
        ("fit_p", "its fit p"),
        ("d_coarse", "d(ε) coarse"),
        ("d_fine", "d(ε) finest resolved"),
        ("slope", "slope of d per decade"),
        ("slim", "slim fractal"),
        ("S_bb", "S_bb (headline box)"),
        ("box_cells", "box (cells)"),
        ("wada_all", "Wada, settled a basin"),
        ("wada_exits", "Wada, exits (settled masked)"),
    ),
    "basins.entropy_exponent_by_grid": (
        ("E0", "E0"),
        ("gamma", "γ"),
        ("map", "map"),
        ("grid", "grid"),
        ("alpha", "α from S_b ∝ s^α"),
        ("sides", "box sides s"),
    ),
    "basins.cutoff_prediction": (
        ("E0", "E0"),
        ("gamma", "γ"),
        ("tau2", "τ2"),
        ("eps_c", "measured ε_c"),
        ("eps_c_interval", "measured 1σ interval"),
        ("eps_c_predicted", "predicted ε_c (decision rate λ)"),
        ("eps_c_predicted_kantz_grassberger", "predicted, λ = κ/α"),
        ("eps_c_predicted_interval", "predicted interval (λ ± σ, μ ± σ, κ/α)"),
        ("log10_ratio", "log₁₀ (measured / predicted)"),
        ("statement", "how far apart"),
    ),
    "basins.rate_table": (
        ("E0", "E0"),
        ("decision", "decision rate λ"),
        ("tangent", "λ̄ (tangent dynamics, saddle)"),
        ("kappa_over_alpha", "κ/α"),
        ("decision_over_tangent", "λ / λ̄"),
        ("decision_vs_tangent", "λ against λ̄"),
        ("kappa_over_alpha_vs_tangent", "κ/α against λ̄"),
    ),
    "basins.stretch_table": (
        ("E0", "E0"),
        ("gamma", "γ"),
        ("ln_inv_eps_c", "ln(1/ε_c) measured"),
        ("S_cutoff", "S: share of orbits with Λ > ln(1/ε_c)"),
        ("S_cutoff_range", "S over ε_c's interval"),
        ("stretch_mean_history", "Λ of the mean history"),
        ("S_mean_history", "S there"),
        ("stretch_own_history", "Λ of the own-μ history"),
        ("S_own_history", "S there"),
    ),
    "basins.cutoff_saddle": (
        ("E0", "E0"),
        ("gamma", "γ"),
        ("eps_c", "measured ε_c"),
        ("eps_c_interval", "measured 1σ interval"),
        ("eps_c_tangent", "predicted: λ̄, ensemble μ"),
        ("eps_c_tangent_interval", "its interval"),
        ("verdict_tangent", "measured against it"),
        ("mu_own", "μ of the deciding orbits"),
        ("eps_c_tangent_own", "predicted: λ̄, their μ"),
        ("eps_c_tangent_own_interval", "its interval"),
        ("verdict_tangent_own", "measured against it"),
    ),
    "saddle.saddle": (
        ("system", "system"),
        ("ratio", "E/E_c"),
        ("kappa", "κ"),
        ("lyapunov", "λ̄"),
        ("d1_section", "D₁ (section)"),
        ("d1_section_implied", "2(1 − κ/λ̄)"),
        ("predicted", "λ̄ (1 − d₁)"),
        ("verdict", "κ against λ̄ (1 − d₁)"),
        ("d1_err_largest", "largest part of D₁'s error"),
        ("d1_range_floor", "D₁'s range ended below by"),
    ),
    "saddle.lines": (
        ("system", "system"),
        ("ratio", "E/E_c"),
        ("d1", "d₁ = D₁/2 (section)"),
        ("d1_lines", "d₁ on lines"),
        ("d1_implied", "1 − κ/λ̄"),
        ("n_points", "survivors"),
        ("eps_range", "ε fitted"),
        ("verdict", "κ against λ̄ (1 − d₁ on lines)"),
    ),
    "saddle.scales": (
        ("system", "system"),
        ("ratio", "E/E_c"),
        ("d1", "section D₁/2"),
        ("d1_section_scales", "lines, section's band"),
        ("band_0.0001", "lines 10⁻⁴–10⁻³"),
        ("d1_implied", "1 − κ/λ̄"),
        ("z_implied", "z (smallest band)"),
    ),
    "saddle.gap": (
        ("system", "system"),
        ("ratio", "E/E_c"),
        ("gap", "1 − κ/λ̄ − d₁"),
        ("z", "z"),
        ("left_lines", "left: d₁ on lines"),
        ("left_small_scales", "left: lines, smallest band"),
        ("left_estimator", "left: fixed radius"),
    ),
    "saddle.dimensions": (
        ("system", "system"),
        ("ratio", "E/E_c"),
        ("d0", "d₀ = 1 − α"),
        ("d0_eps_range", "ε fitted"),
        ("d0_fit_p", "fit p"),
        ("d1", "d₁ = D₁/2"),
        ("check", "d₀ ≥ d₁ − 2σ"),
    ),
    "operator.mixed_phase_space": (
        ("energy", "E"),
        ("probes", "KAM probes"),
        ("trapped_boxes", "censored boxes"),
        ("trapped_share_of_saddle_class", "their share of the saddle's class"),
        ("kappa_without_trapped_boxes", "κ without them"),
    ),
    "operator.cmeasure_distances": (
        ("fig1_energy", "fig1 at E"),
        ("operator_energy", "operator at E"),
        ("measure", "operator's measure"),
        ("n", "fig1 points"),
        ("box", "ε"),
        ("hellinger_debiased", "debiased Hellinger"),
        ("hellinger_debiased_lo", "lo"),
        ("hellinger_debiased_hi", "hi"),
        ("hellinger_noise", "noise"),
    ),
    "operator.cmeasure_convergence": (
        ("energy", "E"),
        ("box", "box side"),
        ("samples_per_box", "samples per box"),
        ("kappa", "κ"),
        ("hellinger_debiased", "debiased Hellinger (ε = 0.1)"),
        ("lo", "lo"),
        ("hi", "hi"),
    ),
    "operator.dissipative.P_at": (
        ("t", "t"),
        ("sim", "simulated", "sim_err"),
        ("operator", "operator (box × E)"),
        ("reduced", "reduced, ρ(E) alone"),
    ),
    "operator.cost": (
        ("energy", "E"),
        ("pt_orbit_time_1pct", "P(t) route for 1 %"),
        ("op_orbit_time_1pct", "operator for 1 % (lower bound)"),
        ("pt_rel", "P(t): its rel. error"),
        ("op_rel", "operator: its rel. error"),
        ("pt_rel_at_op_cost", "P(t) at the operator's cost"),
    ),
    "operator.kappa_ulam": (
        ("energy", "E"),
        ("box", "finest box"),
        ("kappa", "κ_Ulam finest boxes", "err"),
        ("kappa_stat_err", "σ bootstrap"),
        ("discretisation_bias", "linear box bias"),
        ("fig2_kappa", "fig2 κ0", "fig2_err"),
        ("z_vs_fig2", "z vs κ0 (both errors)"),
        ("fig2_kappa_cm", "fig2 κ crossings", "fig2_kappa_cm_err"),
        ("kappa_map_per_return", "−ln ρ(P) per return"),
        ("mean_return_time", "⟨T⟩"),
    ),
    # one record per energy, in two tables that fit the page: the residuals, then what the error and bias are made of
    "operator.kappa_convergence": (
        ("energy", "E"),
        ("kappa_inf", "κ∞", "err"),
        ("kappa0", "fig2 κ0"),
        ("residual_kappa0", "κ∞/κ0 − 1"),
        ("verdict_kappa0", "vs κ0"),
        ("kappa_cm", "fig2 κ crossings"),
        ("residual_kappa_cm", "κ∞/κ_cm − 1"),
        ("verdict_kappa_cm", "vs κ_cm"),
    ),
    "operator.kappa_convergence@parts": (
        ("energy", "E"),
        ("kappa_finest", "κ finest boxes"),
        ("kappa_inf", "κ∞", "err"),
        ("stat_err", "σ stat (bootstrap)"),
        ("model_err", "σ model (M^−1/2 vs M^−1)"),
        ("cut_nu", "c-measure on cut boxes"),
        ("cut_weight", "flux weight on cut boxes"),
        ("note", "note"),
    ),
}


#: a number in e-notation inside a text cell ("ε_c < 1e-10"), written as the numbers of the table are
_E_NOTATION = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)e([+-]?\d+)(?![\w.])")


def _power_of_ten(m) -> str:
    return f"{m.group(1)}×10<sup>{int(m.group(2))}</sup>"


def spec_table(recs, spec=None) -> str:
    """Markdown table of records with the columns ``spec`` ((key, header[, error key]); default every key): a key
    with an error (default its sibling ``<key>_err``) as value ± error rounded to the error, a key with a sibling
    ``<key>_upper`` (a count of 0) as its one-sided bound, None or NaN as "—". Every number in one notation: a
    magnitude outside [1e-3, 1e5) as a×10<sup>b</sup>, in a value ± error and in a text cell alike."""
    import math

    if spec is None:
        cols = []
        for r in recs:
            cols.extend(k for k in r if k not in cols and not k.endswith("_err"))
        spec = [(c, c) for c in cols]
    spec = [(c[0], c[1], c[2] if len(c) > 2 else c[0] + "_err") for c in spec]
    spec = [c for c in spec if any(r.get(c[0]) is not None for r in recs)]

    def cell(r, k, ek):
        v, e = r.get(k), r.get(ek)
        if isinstance(v, dict) and "value" in v:  # a measured value as the JSON writes it: {value, err}
            v, e = v["value"], v.get("err")
        if v is None or (isinstance(v, float) and math.isnan(v)):
            return "—"
        if _is_num(r.get(k + "_upper")) or _is_num(r.get(k + "_lower")):  # a count of 0 (or all): its bound
            from hhscatter.publish.formatting import format_bound

            bound = format_bound(r.get(k + "_upper"), r.get(k + "_lower"), r.get(k + "_cl", 0.95))
            return _E_NOTATION.sub(_power_of_ten, bound)
        if k.startswith("z") and _is_num(v):  # a distance in σ
            return f"{v:+.1f}"
        if k.startswith("residual") and _is_num(v):  # a relative difference, in per cent
            ok = _is_num(e) and math.isfinite(e) and e > 0
            return (fmt_err(100 * v, 100 * e) if ok else f"{100 * v:+.2f}") + " %"
        if _is_num(v) and _is_num(e) and math.isfinite(e) and e > 0:
            from hhscatter.publish.formatting import format_value_err

            return format_value_err(v, e, html=True)  # a power of ten as the other cells write it
        if isinstance(v, list):
            return "[" + ", ".join(fmt_num(x, 3) if _is_num(x) else str(x) for x in v) + "]"
        return fmt_num(v) if _is_num(v) else _E_NOTATION.sub(_power_of_ten, str(v))

    out = ["| " + " | ".join(_cell(h) for _, h, _ in spec) + " |", "|" + "---|" * len(spec)]
    out.extend("| " + " | ".join(_cell(cell(r, k, ek)) for k, _, ek in spec) + " |" for r in recs)
    return "\n".join(out) + "\n"


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


def comparison_table(rows, scale=None) -> str:
    """Markdown table of paper-vs-ours rows {quantity, ours, err, paper, unit, verdict, note}; verdicts by the rule."""
    from hhscatter.publish.formatting import comparison_table as table

    return table(rows, scale=scale)


def _embed_markdown(text: str, assets: Path, rel) -> str:
    """A summary written for its own folder, embedded in a page: headings demoted, links re-based,
    ``|x|`` inside table cells escaped, plain-text tables fenced (hhscatter.publish.formatting.embed_markdown)."""
    from hhscatter.publish.formatting import embed_markdown

    text = embed_markdown(text)

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
                    metavar = a.metavar or ("{" + ",".join(map(str, a.choices)) + "}" if a.choices else a.dest.upper())
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


# -- MkDocs entry points -------------------------------------------------------
STUDIES_NAV = "Studies"


def study_pages(root: Path) -> list:
    """Nav entries {title: 'studies/<name>.md'}, one per study folder of ``root/studies`` (dependency order)."""
    from hhscatter.studies.graph import studies

    return [{s.title: f"studies/{s.name}.md"} for s in studies(root / "studies")]


def on_config(config, **kwargs):
    """Fill the nav's Studies section from the study folders (mkdocs.yml lists only its index pages)."""
    root = Path(config["config_file_path"]).resolve().parent
    for item in config["nav"] or []:
        if isinstance(item, dict) and STUDIES_NAV in item:
            item[STUDIES_NAV] = [*item[STUDIES_NAV], *study_pages(root)]
    config["watch"] = [*config.get("watch", []), str(root / "studies")]  # `make docs-serve` sees page.md edits
    return config


def on_files(files, config, **kwargs):
    """Each study's page text lives in its folder (studies/<name>/page.md); it is served as studies/<name>.md."""
    from mkdocs.structure.files import File

    root = Path(config["config_file_path"]).resolve().parent
    for page in sorted((root / "studies").glob("*/page.md")):
        if (page.parent / "study.toml").exists():
            files.append(File.generated(config, f"studies/{page.parent.name}.md", abs_src_path=str(page)))
    return files


_H2 = re.compile(r"^## ", re.M)
_FENCE = re.compile(r"^(```|~~~).*?^\1\s*$", re.M | re.S)


def figure_first(markdown: str, summary: str = "") -> str:
    """A study page in reading order: what it shows, the figure, the rest, then the configuration folded.

    The ``## `` section that holds the ``hh:study-figure`` marker moves up to just after the page's
    preamble (title and first lines); the one that holds ``hh:study-params`` moves down to just before
    the implementation (``hh:study-module``) or to the end, and is folded (``study-params`` renders as a
    closed ``???`` block). Other sections keep their order. Headings inside code fences are not split on.
    ``summary`` (the study.toml's ``[about] summary``) is said in one line above the figure.
    """
    fenced = [m.span() for m in _FENCE.finditer(markdown)]
    cuts = [m.start() for m in _H2.finditer(markdown) if not any(a <= m.start() < b for a, b in fenced)]
    if not cuts:
        return markdown
    head, parts = markdown[: cuts[0]], [markdown[a:b] for a, b in zip(cuts, [*cuts[1:], len(markdown)])]
    parts = [p if p.endswith("\n\n") else p.rstrip("\n") + "\n\n" for p in parts]

    def take(marker):
        hit = [p for p in parts if f"<!-- hh:{marker} " in p]
        for p in hit:
            parts.remove(p)
        return hit

    figure, params = take("study-figure"), take("study-params")
    module = [i for i, p in enumerate(parts) if "<!-- hh:study-module " in p]
    at = module[0] if module else len(parts)
    parts[at:at] = params
    if summary:
        head = head.rstrip("\n") + f"\n\n**What it shows:** {summary}.\n\n"
    return head + "".join(figure + parts)


def on_page_markdown(markdown, page, config, files, **kwargs):
    """Replace every ``<!-- hh:... -->`` marker of a page with its generated Markdown (study pages: figure first)."""
    if "<!-- hh:" not in markdown:
        return markdown
    fig = re.search(r"<!--\s*hh:study-figure\s+([\w.-]+)", markdown)
    if fig:
        from hhscatter.studies.graph import studies

        about = {s.name: s.summary for s in studies(Path(config["config_file_path"]).resolve().parent / "studies")}
        markdown = figure_first(markdown, about.get(fig.group(1), ""))
        # a study page gives its figure the width of the page: the table of contents (a few headings) goes
        meta = getattr(page, "meta", None)
        if isinstance(meta, dict):
            meta["hide"] = [*meta.get("hide", []), "toc"]
    docs = Path(config["docs_dir"])
    root = Path(config["config_file_path"]).resolve().parent
    page_dir = (docs / page.file.src_uri).parent
    r = Renderer(root, docs, page_dir)
    from hhscatter.publish.numbers import NumberRefError

    def sub(m):
        indent, kind, arg = m.group(1), m.group(2), m.group(3)
        fn = getattr(r, kind.replace("-", "_"), None)
        if fn is None:
            raise ValueError(f"{page.file.src_uri}: unknown docs marker hh:{kind}")
        try:
            out = fn(arg)
        except NumberRefError as e:
            from mkdocs.exceptions import PluginError

            raise PluginError(f"{page.file.src_uri}: hh:{kind}: {e}") from None
        out = typographic_minus(out)
        # a marker inside an admonition (indented) gets its content indented alike
        return "\n".join(indent + line if line.strip() else "" for line in out.splitlines()) if indent else out

    return _MARKER.sub(sub, markdown)


def _pct(v, e=None) -> str:
    if not _is_num(v):
        return "—"
    return fmt_err(100 * v, 100 * e) + " %" if _is_num(e) else f"{fmt_num(100 * v, 3)} %"


def _bounded(v, e, upper=None, cl=0.95, *, pct=False, syst=None, syst2=None, n=None) -> str:
    """A fraction as value ± stat (± syst (± syst2)), or, at a count of 0, its one-sided bound "< b (95 %)" (a record
    written before bounds were recorded: from its number of orbits ``n``, by the same estimator)."""
    from hhscatter.analysis.stats.intervals import fraction_with_bound
    from hhscatter.publish.formatting import format_bound

    if not _is_num(upper) and v == 0 and _is_num(n) and n > 0:
        upper = fraction_with_bound(0, int(n), cl=cl).upper
    if _is_num(upper):
        return format_bound(upper, cl=cl, pct=pct)
    if pct:
        out = _pct(v, e)
        for x in (syst, syst2):
            if _is_num(x) and x > 0 and _is_num(e) and e > 0:
                out = out[: -len(" %")] + f" ± {fmt_err(100 * x, 100 * e).split(' ± ')[0]} %"  # stat's decimals
        return out
    return _ve_cell({"value": v, "err": e})


def _ve_cell(d) -> str:
    return (
        fmt_err(d["value"], d["err"])
        if d and _is_num(d.get("value")) and _is_num(d.get("err"))
        else (fmt_num(d["value"]) if d and _is_num(d.get("value")) else "—")
    )


#: a validity-map cell of an energy of the claims' grid that a scale's evidence did not run
NOT_RUN = "not run at this scale"


def _validity_table(doc, vm, n_of) -> str:
    """The validity map: per (system, E/E_c) the regular fraction's count, claim 1's κ0 with the numbers that decide
    "defined" (by the record's stated rule, ``validity_rules``), claim 2, one exponential, the plateau; the energies
    of the claims' grid (``config.study.ratios``) the record has no cell for are rows "not run at this scale"."""
    yn = {True: "yes", False: "no", None: "—"}
    rules = doc.get("validity_rules") or {}
    out = [
        "\n**Validity map** (disk ICs): the regular fraction beside claim 1's verdict (κ0 with all orbits, the "
        "paper's convention) and claim 2's where tested, and whether the non-regular orbits decay as one "
        "exponential"
        + (
            f". Regular fraction: {rules['regular_fraction']}. κ0: {rules['kappa0_defined']} ({rules['kappa0_source']})"
            if rules
            else ""
        )
        + "\n",
        "| system | E/E_c | regular fraction | κ0 (claim 1) | claim 2 | one exponential (non-regular) | "
        "plateau P∞ > 3σ |",
        "|---|---|---|---|---|---|---|",
    ]
    grid = ((doc.get("config") or {}).get("study") or {}).get("ratios") or []
    rows = [(v["label"], v["e_ratio"], v) for v in vm]
    have = {(lab, round(r, 9)) for lab, r, _ in rows}
    for lab in dict.fromkeys(lab for lab, _, _ in rows):
        rows += [(lab, float(r), None) for r in grid if (lab, round(float(r), 9)) not in have]
    order = {lab: i for i, lab in enumerate(dict.fromkeys(lab for lab, _, _ in rows))}
    for lab, r, v in sorted(rows, key=lambda x: (order[x[0]], x[1])):
        if v is None:
            out.append(f"| {lab} | {r:g} | {NOT_RUN} | {NOT_RUN} | — | — | — |")
            continue
        total = v.get("regular_err_total")
        regular = (
            _bounded(v["regular_fraction"], total, v.get("regular_fraction_upper"), pct=True, n=n_of.get(v.get("id")))
            if _is_num(total)
            else _bounded(
                v["regular_fraction"],
                v["regular_err"],
                v.get("regular_fraction_upper"),
                pct=True,
                syst=v.get("regular_syst"),
                n=n_of.get(v.get("id")),
            )
        )
        if v.get("n_regular") is not None and v.get("n"):
            regular = f"{v['n_regular']} of {v['n']}: {regular}"
        if v.get("kappa0_verdict"):
            k = v.get("kappa0") or {}
            shown = _is_num(k.get("value")) and v["kappa0_defined"]
            kappa = (f"{_ve_cell(k)}; " if shown else "") + v["kappa0_verdict"]
        else:
            kappa = NOT_RUN if v["kappa0_defined"] is None else yn[v["kappa0_defined"]]
        exp = yn[v["exponential"]] if v["exponential"] is not None else v.get("exponential_verdict") or "—"
        out.append(
            f"| {lab} | {r:g} | {regular} | {_cell(kappa)} | {_cell(v['claim2'] or '—')} | {exp} | {yn[v['plateau']]} |"
        )
    return "\n".join(out)


def evidence_tables(doc) -> str:
    """Markdown tables of a generality JSON's evidence: regular fraction (E/E_c × systems per IC convention),
    long-time escape (disk ICs), the validity map and the r_esc sensitivity."""
    out = []
    reg = doc["regular_fraction"]
    ratios = sorted({r["e_ratio"] for r in reg})
    out.append(
        "**Regular fraction** (orbits the shadow indicator calls regular, of all orbits; ± binomial 1σ ± the "
        "systematic of the threshold, the largest shift with the threshold a decade either side, ± the indicator's "
        "systematic where a labelled set was run (the share of all orbits the variational FTLE would move across "
        "the class line); where no orbit is regular, the one-sided 95 % upper bound)\n"
    )
    # energies down, (system, ICs) across: the grid has as many energies as it likes and the table stays as wide as
    # its systems (at 1280 px no column is scrolled out of view)
    pairs = list(dict.fromkeys((r["label"], r["ics"]) for r in reg))
    cells = {
        (r["label"], r["ics"], r["e_ratio"]): _bounded(
            r["fraction"],
            r["err"],
            r.get("fraction_upper"),
            r.get("fraction_cl", 0.95),
            pct=True,
            syst=r.get("syst"),
            syst2=r.get("syst_indicator"),
            n=r.get("n"),
        )
        for r in reg
    }
    out.append("| E/E_c | " + " | ".join(f"{lab}<br>{ics}" for lab, ics in pairs) + " |")
    out.append("|---|" + "---|" * len(pairs))
    for x in ratios:
        out.append(f"| {x:g} | " + " | ".join(cells.get((lab, ics, x), "—") for lab, ics in pairs) + " |")
    lab = [r for r in reg if r.get("labelled")]
    if lab:
        L0 = lab[0]["labelled"]
        out.append(
            f"\n**Labelled sets** (the band's orbits and a sample either side, run again with the tangent dynamics to "
            f"t = {L0['t_label']:g} and labelled by the variational FTLE λ_T: regular below {L0['ftle_regular']:g}, "
            f"chaotic above {L0['ftle_chaotic']:g} or when the orbit leaves; disagreements in the band: regular by the "
            "shadow and chaotic by λ_T, and the reverse; the indicator systematic scales them to the band)\n"
        )
        out.append(
            "| system | E/E_c | labelled | of the band | undecided | shadow regular, λ_T chaotic | the reverse "
            "| outside the band | indicator syst. | threshold syst. |"
        )
        out.append("|---|---|---|---|---|---|---|---|---|---|")
        for r in lab:
            L = r["labelled"]
            out.append(
                f"| {r['label']} | {r['e_ratio']:g} | {L['n_labelled']} | {L['n_band_labelled']} of {L['n_band']} "
                f"| {L['n_undecided']} | {L['disagree_to_chaotic']} | {L['disagree_to_regular']} "
                f"| {L['disagree_outside']} | {_pct(r.get('syst_indicator'))} | {_pct(r.get('syst'))} |"
            )
    P = {(r["label"], r["e_ratio"], r["t"]): r for r in doc.get("survival_long", [])}
    ts = sorted({r["t"] for r in doc.get("survival_long", [])})
    out.append(
        "\n**Long-time escape** (disk ICs, γ = 0; P(t) Kaplan–Meier; P∞, κ_tail: plateau + exponential by "
        "maximum likelihood from t0, censored orbits as censored; κ of the non-regular orbits: one "
        "exponential from t0, p its χ² p-value over cells pooled to ≥ 5 expected orbits; a P of 0 as its "
        "one-sided 95 % upper bound)\n"
    )
    out.append(
        "| system | E/E_c | "
        + " | ".join(f"P({t:g})" for t in ts)
        + " | P∞ | κ_tail | regular share of the orbits inside at t_max | κ non-regular | p |"
    )
    out.append("|---|---|" + "---|" * (len(ts) + 5))
    for f in doc["long_time"]:
        if "disk" not in f["ics"]:
            continue
        ps = [P.get((f["label"], f["e_ratio"], t)) for t in ts]
        out.append(
            f"| {f['label']} | {f['e_ratio']:g} | "
            + " | ".join(
                _bounded(x["P"], x["P_err"], x.get("P_upper"), x.get("P_cl", 0.95), n=f.get("n")) if x else "—"
                for x in ps
            )
            + " | "
            + " | ".join(
                [
                    _bounded(f.get("P_inf"), f.get("P_inf_err"), f.get("P_inf_upper"), f.get("P_inf_cl", 0.95)),
                    _ve_cell({"value": f.get("kappa_inf"), "err": f.get("kappa_inf_err")}),
                    _pct(f.get("regular_fraction_of_censored")),
                    _ve_cell({"value": f.get("kappa_nonregular"), "err": f.get("kappa_nonregular_err")}),
                    fmt_num(f["p_nonregular"], 2)
                    if _is_num(f.get("p_nonregular"))
                    else (f.get("exponential_verdict") or "—"),
                ]
            )
            + " |"
        )
    vm = doc.get("validity_map", [])
    n_of = {r.get("id"): r.get("n") for r in reg}
    if vm:
        out.append(_validity_table(doc, vm, n_of))
    rs = doc.get("resc", [])
    if rs:
        out.append("\n**r_esc sensitivity** (the same N and rules at each escape radius; windows of μ's fit)\n")
        out.append(
            "| system | r_esc | window | μ measured | μ predicted (c-measure) | μ own ⟨K⟩ | moment test "
            "(own − predicted) | 2⟨K⟩/E at E0 (measured) | at E0 interpolated (without E0) |"
        )
        out.append("|---|---|---|---|---|---|---|---|---|")
        for r in rs:
            out.append(
                f"| {r['label']} | {r['r_esc']:.3g}{' (default)' if r['default'] else ''} | "
                f"[{r['window'][0]:g}, {r['window'][1]:g}] | {_ve_cell(r['mu_measured'])} | "
                f"{_ve_cell(r['mu_predicted'])} | {_ve_cell(r['mu_own_K'])} | {_ve_cell(r['moment_test'])} | "
                f"{_ve_cell(r['kinetic_at_E0'])} | {fmt_num(r['kinetic_at_E0_interpolated_without_E0'])} |"
            )
    rk = doc.get("resc_kappa", [])
    if rk:
        out.append(
            "\n**κ0 at two escape radii** (the same orbits at each radius, the same rules; κ0 of all orbits "
            "(plateau windows, the paper's convention) and of the orbits escaping at both radii; shift = "
            "κ0(r_esc)/κ0(default) − 1 ± its paired error: a bootstrap over the orbits, the same resampled orbits at "
            "both radii and the window rule re-applied to each; beside it the two errors in quadrature, which "
            "ignore that the radii share their orbits; verdict against no shift by the one rule on the paired "
            "error)\n"
        )
        out.append(
            "| system | E/E_c | κ0 of | default r_esc | κ0 there | r_esc | κ0 there | shift (paired error) "
            "| quadrature error | verdict |"
        )
        out.append("|---|---|---|---|---|---|---|---|---|---|")
        for r in rk:
            out.append(
                f"| {r['label']} | {r['e_ratio']:g} | {'all orbits' if r['convention'] == 'plateau' else 'escaping'} "
                f"| {r['r_esc_default']:.3g} | {_ve_cell(r['kappa_default'])} | "
                f"{r['r_esc']:.3g} ({r['r_esc_over_saddle']:.3g} r_s) | {_ve_cell(r['kappa'])} | "
                f"{_ve_cell(r['shift'])} | {fmt_num(r.get('shift_err_unpaired'), 2)} | {_cell(r['verdict'])} |"
            )
    return "\n".join(out) + "\n"
