"""The built site in a real browser: every equation shows ink, every figure loads, search works from disk.

The site is built once (``mkdocs build --strict`` into a temporary folder, ~10 s) and opened from disk
(``file://``, as a reader who downloaded it would) in headless Chromium, Debian's package, driven by the
``playwright`` package of the docs extra with ``executable_path`` (playwright's own browser downloads are never
used). ``make test`` installs Chromium when it is missing (``make chromium``: apt-get, as root); where none can be
had these tests are skipped with a message that says so.

What is checked, on every page of the site:

* every ``.arithmatex`` element (pymdownx's marked LaTeX) became one MathJax ``mjx-container`` and a screenshot
  of it has dark pixels (the issue: containers were built but the glyphs' CSS had been dropped, so nothing
  showed); no MathJax error node (``mjx-merror``);
* every ``<img>`` loaded (``naturalWidth > 0``);
* no JavaScript error on any page;
* the search box, typed into on ``index.html`` opened from disk, lists results (Material's ``offline`` plugin).
"""

from __future__ import annotations

import io
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = os.environ.get("HHSCATTER_CHROMIUM", "/usr/bin/chromium")
#: Chromium flags for a sandboxless container without network: no first-run UI, no background downloads
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
INK = 110  # a pixel darker than this (0-255 grey) is ink: text is near black, the page white
MIN_INK_PIXELS = 3


def _need_browser():
    sync_api = pytest.importorskip("playwright.sync_api", reason="no playwright: pip install -e '.[docs]'")
    if not (os.path.isfile(CHROMIUM) and os.access(CHROMIUM, os.X_OK)):
        pytest.skip(
            f"no Chromium at {CHROMIUM}: `make chromium` installs Debian's package (needs root and apt); "
            "the browser tests of the docs did not run"
        )
    return sync_api


@pytest.fixture(scope="module")
def site(built_site):
    return built_site  # tests/docs/conftest.py: built once per session, shared with the site checks


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    sync_api = _need_browser()
    user_data = tmp_path_factory.mktemp("chromium-profile")
    with sync_api.sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(
            str(user_data), executable_path=CHROMIUM, args=FLAGS, headless=True, viewport={"width": 1400, "height": 900}
        )
        try:
            yield ctx
        finally:
            ctx.close()
            shutil.rmtree(user_data, ignore_errors=True)


def _ink(png: bytes) -> int:
    from PIL import Image

    grey = np.asarray(Image.open(io.BytesIO(png)).convert("L"))
    return int((grey < INK).sum())


def _open(ctx, path: Path):
    page = ctx.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(path.as_uri(), wait_until="load")
    return page, errors


def _pages(site: Path):
    return sorted(site.rglob("*.html"))


def test_ink_detector_sees_text_and_not_a_blank(browser, tmp_path):
    """The dark-pixel check itself: ink in a rendered word, none in an empty box of the same size."""
    html = tmp_path / "probe.html"
    html.write_text(
        '<body style="background:#fff"><span id="a" style="font-size:20px">κ = 0.18</span>'
        '<span id="b" style="display:inline-block;width:80px;height:20px"></span></body>'
    )
    page, _ = _open(browser, html)
    assert _ink(page.locator("#a").screenshot()) >= MIN_INK_PIXELS
    assert _ink(page.locator("#b").screenshot()) == 0
    page.close()


def test_every_equation_on_every_page_shows_ink(site, browser):
    checked, blank, failed = 0, [], []
    for path in _pages(site):
        n_math = path.read_text(errors="replace").count('class="arithmatex"')
        if not n_math:
            continue
        page, errors = _open(browser, path)
        page.wait_for_function("window.MathJax && MathJax.startup && MathJax.startup.promise", timeout=20_000)
        page.evaluate("MathJax.startup.promise")
        rel = path.relative_to(site).as_posix()
        containers = page.locator(".arithmatex mjx-container")
        assert containers.count() == n_math, f"{rel}: {n_math} equations, {containers.count()} typeset"
        assert page.locator("mjx-merror").count() == 0, f"{rel}: MathJax error in an equation"
        for i in range(n_math):
            box = containers.nth(i)
            box.scroll_into_view_if_needed()
            if _ink(box.screenshot()) < MIN_INK_PIXELS:
                tex = box.evaluate("e => e.closest('.arithmatex').textContent")
                blank.append(f"{rel} #{i}: {tex[:60]!r}")
            checked += 1
        failed += [f"{rel}: {e}" for e in errors]
        page.close()
    assert checked >= 14, f"only {checked} equations found in the site (equations.md alone has 14)"
    assert not blank, f"{len(blank)} of {checked} equations show no ink:\n" + "\n".join(blank[:20])
    assert not failed, "JavaScript errors:\n" + "\n".join(failed)


def test_no_panel_is_shown_wider_than_it_is(site, browser):
    """At 1280 px a study figure or a panel of one is shown at its natural width or narrower, never upscaled."""
    checked, upscaled = 0, []
    for path in sorted((Path(site) / "studies").glob("*.html")):
        if "hh-figure" not in path.read_text(errors="replace"):
            continue
        page, _ = _open(browser, path)
        page.set_viewport_size({"width": 1280, "height": 900})
        sizes = page.evaluate(
            "Array.from(document.querySelectorAll('figure.hh-figure img'), "
            "i => [i.getAttribute('src'), i.naturalWidth, i.getBoundingClientRect().width])"
        )
        upscaled += [f"{path.name}: {src} {shown:.0f} px > {nat} px" for src, nat, shown in sizes if shown > nat + 1]
        checked += len(sizes)
        page.close()
    assert checked >= 10, f"only {checked} panels checked"
    assert not upscaled, "panels shown wider than their pixels:\n" + "\n".join(upscaled)


#: the right edge of a results table's verdict column (the column headed "verdict…", else its last column: the
#: reading) and of the box that clips it (the nearest ancestor that scrolls, the table itself included), at 1280 px;
#: folded blocks are opened first; tables of raw JSON records (every head in code) are left out
_VERDICT_EDGES = """() => {
  document.querySelectorAll('article details').forEach(d => { d.open = true; });
  const out = [];
  document.querySelectorAll('article table').forEach((t, i) => {
    const heads = Array.from(t.rows[0] ? t.rows[0].cells : []);
    if (!heads.length || heads.every(h => h.querySelector('code'))) return;
    let v = heads.findIndex(h => h.textContent.trim().toLowerCase().startsWith('verdict'));
    if (v < 0) v = heads.length - 1;
    let right = window.innerWidth;
    for (let e = t; e && e !== document.body; e = e.parentElement) {
      if (getComputedStyle(e).overflowX !== 'visible') right = Math.min(right, e.getBoundingClientRect().right);
    }
    out.push([i, heads[v].textContent.trim(), heads[v].getBoundingClientRect().right, right]);
  });
  return out;
}"""


def test_no_results_table_scrolls_its_verdict_out_of_view(site, browser):
    """At 1280 px the verdict column of every results table on the home page, the studies index, the study pages,
    the benchmarks page and the tutorial's outputs (the column headed "verdict", else the last one, where the tables
    put their reading) lies inside the viewport and inside the box that would scroll it: the reader sees it without
    scrolling the table sideways."""
    checked, hidden = 0, []
    pages = [
        Path(site) / "index.html",
        *sorted((Path(site) / "studies").glob("*.html")),
        Path(site) / "benchmarks" / "index.html",
        Path(site) / "tutorial.html",
    ]
    for path in pages:
        page, _ = _open(browser, path)
        page.set_viewport_size({"width": 1280, "height": 900})
        for i, head, right, clip in page.evaluate(_VERDICT_EDGES):
            checked += 1
            if right > clip + 1:
                hidden.append(f"{path.name} table {i} ({head!r}): ends at {right:.0f} px, visible to {clip:.0f} px")
        page.close()
    assert checked >= 40, f"only {checked} results tables measured"
    assert not hidden, f"{len(hidden)} tables scroll their verdict out of view at 1280 px:\n" + "\n".join(hidden)


def test_every_figure_on_every_page_loads(site, browser):
    checked, broken = 0, []
    for path in _pages(site):
        if "<img" not in path.read_text(errors="replace"):
            continue
        page, errors = _open(browser, path)
        sizes = page.evaluate("Array.from(document.images, i => [i.getAttribute('src'), i.complete, i.naturalWidth])")
        rel = path.relative_to(site).as_posix()
        broken += [f"{rel}: {src}" for src, complete, width in sizes if not (complete and width > 0)]
        broken += [f"{rel}: JavaScript error {e}" for e in errors]
        checked += len(sizes)
        page.close()
    assert checked >= 10, f"only {checked} figures in the site"
    assert not broken, "figures that do not load:\n" + "\n".join(broken)


def test_search_works_from_disk(site, browser):
    """Typed into the search box of index.html opened as a file, queries list matching pages. The index (~1 MB)
    is built in a worker when the page loads; a query typed before it is ready is retyped (up to 90 s). The list
    of the previous query stays on screen until the worker answers, so the first result is read until it matches
    the query (5 s per typing), not once."""
    import re
    import time

    from playwright.sync_api import expect as page_expect

    page, errors = _open(browser, site / "index.html")
    box = page.locator("input.md-search__input")
    items = page.locator(".md-search-result__item")
    for query, expect in (("escape rate", "escape"), ("basin", "basin")):
        deadline = time.monotonic() + 90
        while True:
            box.click()
            box.fill("")
            box.type(query)
            try:
                page_expect(items.first).to_contain_text(re.compile(expect, re.IGNORECASE), timeout=5_000)
                break
            except AssertionError:  # the index is not built yet, or the list is still the previous query's
                shown = items.first.inner_text()[:200] if items.count() else "(no results)"
                assert time.monotonic() < deadline, f"no result for {query!r} within 90 s; first: {shown!r}"
    assert not errors, errors
    page.close()


def test_the_site_loads_nothing_from_the_network(site):
    """Offline: no page links a script, stylesheet or image from another host (CDNs, fonts, the search shim)."""
    import re

    remote = re.compile(r"""<(?:script|img|link)\b[^>]*\b(?:src|href)=["'](?:https?:)?//""", re.IGNORECASE)
    hits = [
        f"{p.relative_to(site)}: {m.group(0)[:120]}"
        for p in _pages(site)
        for m in remote.finditer(p.read_text(errors="replace"))
        if 'rel="canonical"' not in m.group(0)
    ]
    assert not hits, "\n".join(hits[:20])


def test_api_pages_show_no_literal_bullet_stars(site):
    """Docstring lists written with '*' render as lists (docs/_hooks/griffe_roles.py), not as '* item' text."""
    import re

    hidden = re.compile(r"<script\b.*?</script>|<pre\b.*?</pre>|<code\b.*?</code>", re.DOTALL)
    star = re.compile(r"(?:<p>|<br ?/?>|\n)\s*\\?\*\s+\S[^<\n]{0,50}")
    hits = {
        p.relative_to(site).as_posix(): star.findall(hidden.sub("", p.read_text(errors="replace")))[:2]
        for p in _pages(site)
    }
    hits = {k: v for k, v in hits.items() if v}
    assert not hits, hits
    api_page = (site / "api" / "api" / "rates.html").read_text()  # the notebook API: escape_rates and friends
    for section in ("Parameters:", "Returns:", "Examples:"):
        assert section in api_page, section  # numpy sections parsed by griffe


def test_api_pages_show_no_literal_rst_tables(site):
    """A docstring table renders as a table: reStructuredText "=== ===" borders would show as text (the docstrings
    are Markdown with numpy sections; write tables with pipes)."""
    import re

    hidden = re.compile(r"<script\b.*?</script>|<pre\b.*?</pre>|<code\b.*?</code>", re.DOTALL)
    rule = re.compile(r"={8,}")
    hits = {
        p.relative_to(site).as_posix(): rule.findall(hidden.sub("", p.read_text(errors="replace")))[:1]
        for p in _pages(site)
        if p.relative_to(site).parts[0] == "api"
    }
    hits = {k: v for k, v in hits.items() if v}
    assert not hits, hits
    assert "<table" in (site / "api" / "errors.html").read_text()  # the error family's table


def test_api_examples_show_their_code_as_written(site):
    """A docstring example's ``4 * err`` shows as written, not ``4 \\* err`` (the star escaping skips doctests)."""
    import html
    import re

    code = re.compile(r"<code\b[^>]*>(.*?)</code>", re.DOTALL)
    hits = [
        f"{p.relative_to(site).as_posix()}: {line.strip()[:100]}"
        for p in _pages(site)
        if "/api/" in p.as_posix()
        for block in code.findall(p.read_text(errors="replace"))
        for line in html.unescape(re.sub(r"<[^>]+>", "", block)).splitlines()
        if ">>>" in line and "\\*" in line
    ]
    assert not hits, "\n".join(hits[:20])
