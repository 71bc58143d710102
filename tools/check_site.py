"""Check a built docs site (``make docs`` → site/): links, anchors and what a reader should never see.

    python tools/check_site.py site/            # counts per check, then the first findings of each

Checks, over every HTML page (the text a reader sees: outside maths, code, scripts and the footer):

* ``links``   — a local link or image whose file is missing, or whose ``#anchor`` is no ``id`` of that page
  (anchors compared after percent-decoding, so Greek and other non-ASCII anchors are checked as written);
* ``raw_tex`` — LaTeX outside maths (``^{``, ``_{``, ``\\kappa``, ``\\frac``…): what MathJax never saw;
* ``nan``     — "nan" / "NaN" as a value;
* ``zero_err`` — "± 0.000", "± 0.0": an uncertainty printed with more digits than it has;
* ``workflow`` — the project's own workflow history: issue numbers, the planning folder ``.dev``,
  commit hashes cited as history;
* ``minus``   — a negative number written with the hyphen "-" in place of the minus sign "−" (as the verdicts and
  the rendered numbers write it), on the pages of results and concepts (the API reference and the tutorial, whose
  text quotes Python, are not checked).

The tests (tests/docs/test_site_checks.py) run these over the site built in the suite.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from urllib.parse import unquote, urlsplit

RAW_TEX = re.compile(r"[\^_]\{|\\(?:[A-Za-z]{2,})\b|\\[{}]")
#: "nan" as a printed value (lower case, or signed, or a table cell of its own); "NaN" in the API's prose
#: names the floating-point value and is fine
NAN = re.compile(r"(?<![\w.])(?:[+-]nan|nan)\b(?![\w-])")
ZERO_ERR = re.compile(r"±\s*0\.0+(?![\d]*[1-9])")
WORKFLOW = re.compile(
    r"\bissues?\s*#?\d+\b|#\d{1,3}\b(?=\s*\))|(?<![\w/])\.dev/|\b(?:at|since|from|in|before|after)"
    r"\s+(?:commit\s+)?`?[0-9a-f]{7,12}\b`?",
    re.I,
)
#: a hyphen used as the sign of a number: "-0.26", "(z = -1.1)", "[-0.015, …]", "10^-10"; not "x-1", "grid[-1]"
MINUS = re.compile(r"(?<![\w.\-/\[])-(?=\.?\d)|(?<=\[)-(?=\d+(?:\.\d+)?,)")
#: pages whose text quotes code (Python indices, shell flags): the minus check leaves them
NOT_PROSE = ("api/", "tutorial.html")
_HEX = re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b")


_DROP = re.compile(r"<(pre|code|script|style|footer)\b.*?</\1>", re.S | re.I)
_ARTICLE = re.compile(r"<article\b.*?</article>", re.S)
_ID = re.compile(r"""\s(?:id|name)=["']([^"']+)["']""")
_URL = re.compile(r"""<(?:a|img)\b[^>]*?\s(?:href|src)=["']([^"']*)["']""", re.I)


def reader_text(html: str) -> str:
    """The text of a page's article a reader sees as prose: maths, code, scripts, styles and the footer removed."""
    from bs4 import BeautifulSoup

    m = _ARTICLE.search(html)
    soup = BeautifulSoup(_DROP.sub(" ", m.group(0) if m else html), "html.parser")
    for tag in soup.select(".arithmatex, mjx-container, .md-source-file"):
        tag.decompose()
    return soup.get_text(" ")


def _ids(html: str) -> set[str]:
    import html as h

    return {h.unescape(x) for x in _ID.findall(html)}


def check(site: Path) -> dict[str, list[str]]:
    """{check: ["page: finding", …]} over every HTML page of ``site``."""
    site = Path(site)
    # 404.html is served from the site's root by a web server: its links are absolute on purpose
    pages = sorted(
        p
        for p in site.rglob("*.html")
        if p.name != "404.html" and not {"assets", "javascripts"} & set(p.relative_to(site).parts[:-1])
    )
    ids_cache: dict[Path, set[str]] = {}
    out: dict[str, list[str]] = {k: [] for k in ("links", "raw_tex", "nan", "zero_err", "workflow", "minus")}
    for page in pages:
        rel = page.relative_to(site).as_posix()
        html = page.read_text(errors="replace")
        ids_cache.setdefault(page.resolve(), _ids(html))
        if True:
            for url in _URL.findall(_DROP.sub(" ", html)):
                import html as h

                url = h.unescape(url)
                parts = urlsplit(url)
                if parts.scheme or url.startswith(("//", "mailto:", "data:", "javascript:")):
                    continue
                target = (page.parent / unquote(parts.path)).resolve() if parts.path else page.resolve()
                if parts.path and not target.exists():
                    out["links"].append(f"{rel}: {url} (no such file)")
                    continue
                if parts.fragment and target.suffix == ".html":
                    if target not in ids_cache:
                        ids_cache[target] = _ids(target.read_text(errors="replace"))
                    if unquote(parts.fragment) not in ids_cache[target]:
                        out["links"].append(f"{rel}: {url} (no anchor #{unquote(parts.fragment)})")
        text = reader_text(html)
        checks = [("raw_tex", RAW_TEX), ("nan", NAN), ("zero_err", ZERO_ERR), ("workflow", WORKFLOW)]
        if not rel.startswith(NOT_PROSE):
            checks.append(("minus", MINUS))
        for key, rx in checks:
            for m in rx.finditer(text):
                ctx = " ".join(text[max(0, m.start() - 40) : m.end() + 40].split())
                out[key].append(f"{rel}: …{ctx}…")
    return out


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    site = Path(args[0] if args else "site")
    res = check(site)
    for key, items in res.items():
        print(f"{key:10s} {len(items)}")
    for key, items in res.items():
        for line in items[: int(args[1]) if len(args) > 1 else 8]:
            print(f"  [{key}] {line}")
    return 1 if any(res.values()) else 0


if __name__ == "__main__":
    raise SystemExit(main())
