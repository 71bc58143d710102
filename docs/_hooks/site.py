"""MkDocs hook: maths, the paper's equation and figure labels, and the commit in the footer.

* **Maths, offline.** ``pymdownx.arithmatex`` (generic mode) marks the LaTeX
  of the pages; MathJax 3 typesets it in the browser. The MathJax files are
  not fetched from a CDN: ``on_files`` adds them to the site from the
  ``django-static-mathjax`` wheel (a plain copy of MathJax 3, part of the
  ``docs`` extra), so the build and the site work without a network.
* **Equation references.** Docstrings and pages cite the paper's equations by
  their LaTeX labels, ``Eq. (eqn:kappa_hyperbolic)``; ``on_page_content``
  turns each such label into the equation's number, linked to its entry on
  ``equations.md`` (which is the one list of labels and numbers), and drops
  figure labels (``fig:survprob``) beside the figure number they repeat.
* **Exponents and indices in prose.** Plain-text formulas of pages and
  docstrings (``E0 e^{−μγt}``, ``μ_c^{E1}``, ``Σ_{s∈i}``, written so that
  ``help()`` reads them) are set as superscripts and subscripts
  (``<sup>``/``<sub>``) by ``on_page_content``, outside maths and code: a
  reader never sees a brace of TeX (:func:`scripts_outside_math`).
* **Signs and stars of formulas.** ``on_page_markdown`` writes a negative number's sign "−" on every page, as the
  generated tables and the report do (:func:`hhscatter.publish.formatting.typographic_minus`), and escapes the
  stars of plain-text formulas (``E(t*)``, ``τ*``, ``x**2``) so that two of them never become emphasis
  (:func:`hhscatter.publish.formatting.formula_stars`); in a table a number stays with its "±", "<" or "%"
  (:func:`hhscatter.publish.formatting.keep_together`). Code and maths are left as written.
* **Footer.** ``on_config`` writes the commit (and date) the site was built
  from into the footer, so a page's numbers can be traced to their code.
"""

from __future__ import annotations

import datetime
import importlib.util
import re
from pathlib import Path

MATHJAX_DEST = "javascripts/mathjax"
#: what tex-chtml.js loads: itself, its fonts, TeX extensions (autoload), the menu and accessibility parts
MATHJAX_PARTS = ("tex-chtml.js", "output/chtml/fonts/woff-v2", "input/tex/extensions", "ui", "a11y")

_HEADING = re.compile(r"^###\s+\(([A-Z]?\d+)\).*\{#([\w-]+)\}\s*$", re.M)
_EQREF = re.compile(r"\((eqn?:[\w-]+)\)")
_FIGREF_DUP = re.compile(r"\s*(?:\(fig:[\w-]+\)|= fig:[\w-]+|, fig:[\w-]+)")
_FIGREF = re.compile(r"\bfig:([\w-]+)")
_PRE = re.compile(r"(<pre\b.*?</pre>|<code\b.*?</code>)", re.S)

#: the paper's figures in order (labels from its LaTeX source)
FIGURES = (
    "contour_two_manifolds",
    "kappa-E-dependence",
    "energy_decay",
    "survprob",
    "um_comparison",
    "model_data_comparison",
)


def mathjax_dir() -> Path:
    """The ``es5`` folder of the installed MathJax 3 copy (django-static-mathjax)."""
    spec = importlib.util.find_spec("mathjax")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError(
            "the docs need MathJax from the 'docs' extra: pip install -e '.[docs]' (django-static-mathjax)"
        )
    es5 = Path(next(iter(spec.submodule_search_locations))) / "static" / "mathjax" / "es5"
    if not (es5 / "tex-chtml.js").is_file():
        raise RuntimeError(f"{es5}/tex-chtml.js is missing: reinstall django-static-mathjax")
    return es5


def equation_numbers(docs_dir: Path) -> dict[str, str]:
    """{'eqn:kappa_hyperbolic': '2', …} from the ``### (N) … {#eqn-…}`` headings of equations.md."""
    text = (Path(docs_dir) / "equations.md").read_text()
    return {anchor.replace("-", ":", 1): num for num, anchor in _HEADING.findall(text)}


def link_labels(html: str, numbers: dict, prefix: str) -> str:
    """Equation labels → linked numbers, figure labels → 'Fig. N' (outside <pre> and <code>)."""

    def eq(m):
        label = m.group(1)
        if label not in numbers:
            return m.group(0)
        anchor = label.replace(":", "-", 1)
        return f'(<a href="{prefix}equations.html#{anchor}" title="{label}">{numbers[label]}</a>)'

    def fig(m):
        name = m.group(1)
        return f"Fig. {FIGURES.index(name) + 1}" if name in FIGURES else m.group(0)

    parts = _PRE.split(html)
    for i in range(0, len(parts), 2):  # even indices: outside code
        parts[i] = _FIGREF.sub(fig, _FIGREF_DUP.sub("", _EQREF.sub(eq, parts[i])))
    return "".join(parts)


_TAG = re.compile(r"<(/?)([a-zA-Z][\w-]*)([^>]*)>")
#: elements whose text is never rewritten: code, scripts, and the maths arithmatex marked for MathJax
_KEEP = {"code", "pre", "script", "style", "textarea", "kbd", "samp"}
_VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}


def scripts_outside_math(html: str) -> str:
    """scripts_outside_math(html) -> ``^{…}``/``_{…}`` of the prose set as <sup>/<sub>; code and maths untouched."""
    from hhscatter.publish.formatting import scripts_to_html

    if "^{" not in html and "_{" not in html:
        return html
    out, pos, stack = [], 0, []
    for m in _TAG.finditer(html):
        text = html[pos : m.start()]
        out.append(text if stack else scripts_to_html(text))
        closing, name, attrs = m.group(1), m.group(2).lower(), m.group(3)
        if not closing and name not in _VOID and not attrs.rstrip().endswith("/"):
            keep = name in _KEEP or "arithmatex" in attrs or name.startswith("mjx")
            if keep or stack:
                stack.append(name)
        elif closing and stack and stack[-1] == name:
            stack.pop()
        out.append(m.group(0))
        pos = m.end()
    tail = html[pos:]
    out.append(tail if stack else scripts_to_html(tail))
    return "".join(out)


def build_commit(root: Path) -> str:
    from hhscatter.data.schema import git_commit  # deferred: the package loads when the site is built

    return git_commit(root, length=12, timeout=10) or "unknown commit"


# -- MkDocs entry points ---------------------------------------------------------
def on_config(config, **kwargs):
    root = Path(config["config_file_path"]).resolve().parent
    today = datetime.date.today().isoformat()
    config["copyright"] = f"Site built from commit {build_commit(root)} on {today}."
    return config


def on_files(files, config, **kwargs):
    from mkdocs.structure.files import File

    es5 = mathjax_dir()
    for part in MATHJAX_PARTS:
        src = es5 / part
        for p in [src] if src.is_file() else sorted(q for q in src.rglob("*") if q.is_file()):
            rel = p.relative_to(es5).as_posix()
            files.append(File.generated(config, f"{MATHJAX_DEST}/{rel}", abs_src_path=str(p)))
    return files


def on_page_markdown(markdown, page, config, files, **kwargs):
    from hhscatter.publish.formatting import formula_stars, keep_together, typographic_minus

    return keep_together(formula_stars(typographic_minus(markdown)))


def on_page_content(html, page, config, files, **kwargs):
    numbers = equation_numbers(config["docs_dir"])
    prefix = "../" * page.file.url.count("/")
    return scripts_outside_math(link_labels(html, numbers, prefix))
