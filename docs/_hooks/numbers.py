"""MkDocs hook: result numbers rendered from the committed study JSON at build time.

A page writes ``[[fig2:kappa_fit.c]]`` where it states a result; the build
replaces it with the number read from ``docs/studies/assets[/paper]/fig2.json``
(the headline scale: paper where committed), formatted with the digits its
error allows. The syntax, the scales and the formats are those of
:mod:`hhscatter.publish.numbers` (documented for page authors in
docs/studies/adding.md). A reference that the JSON does not hold fails the
build: a page never shows a stale number. References inside code (fences,
inline code) are left as written, so pages can show the syntax itself.
"""

from __future__ import annotations

from pathlib import Path


def on_page_markdown(markdown, page, config, files, **kwargs):
    from mkdocs.exceptions import PluginError

    from hhscatter.publish.numbers import REF, NumberRefError, render_refs

    if not REF.search(markdown):
        return markdown
    root = Path(config["config_file_path"]).resolve().parent
    try:
        return render_refs(markdown, root, where=page.file.src_uri)
    except NumberRefError as e:
        raise PluginError(f"result numbers: {e}") from None
