"""The API reference, generated from the package: one page per public module and its navigation, in layer order.

A module's page is ``docs/api/<path below hhscatter>.md`` (a package's is ``<path>/index.md``) holding the
mkdocstrings directive ``::: <module>``. A page written by hand at that path (a package's overview in prose)
is used as it is; every other page is generated, so a new module needs no page and no navigation line. The
navigation's "API reference" section is built here: the overview ``api/index.md``, then the layers bottom up
(the order of ``LAYERS`` in ``tools/layer_metrics.py``), inside a layer its subpackages in their own order and
its modules by name.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SECTION = "API reference"
MODULE_PAGE = "::: {mod}\n    options:\n      heading_level: 1\n"
PACKAGE_PAGE = "::: {mod}\n    options:\n      heading_level: 1\n      members: false\n"
SKIP = {"cli", "__main__"}  # the CLI has its own page (cli.md); __main__ is the ``python -m`` door


def _public(parts: list[str]) -> bool:
    return not any(p.startswith("_") for p in parts) and not (len(parts) == 1 and parts[0] in SKIP)


def api_pages(root: Path = ROOT, package: str = "hhscatter") -> dict[str, str]:
    """{page path below docs/: module} for every public module and package below ``package``."""
    pages = {}
    for f in sorted((root / package).rglob("*.py")):
        parts = list(f.relative_to(root / package).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        parts = parts[:-1] if is_pkg else parts
        if not parts or not _public(parts):
            continue
        page = "api/" + "/".join(parts) + ("/index.md" if is_pkg else ".md")
        pages[page] = ".".join([package, *parts])
    return pages


def page_text(page: str, mod: str) -> str:
    """The generated text of ``page`` documenting module ``mod``."""
    return (PACKAGE_PAGE if page.endswith("/index.md") else MODULE_PAGE).format(mod=mod)


def api_nav(pages: dict[str, str], order: list[str], package: str = "hhscatter") -> list:
    """The navigation of the API reference for ``pages`` ({page: module}), layers in ``order``."""
    tree: dict = {}
    for page, mod in pages.items():
        node = tree
        for part in mod.split(".")[1:]:
            node = node.setdefault(part, {})
        node[""] = page

    def rank(name: str, keys: list[str]) -> tuple:
        return (keys.index(name) if name in keys else len(keys), name)

    def build(node: dict, prefix: str, keys: list[str]) -> list:
        out = [node[""]] if "" in node else []
        for name in sorted((k for k in node if k), key=lambda k: rank(k, keys)):
            child = node[name]
            sub = [k.split(".", 1)[1] for k in order if k.startswith(f"{name}.")]
            if set(child) == {""}:  # a module
                out.append({name if prefix else f"{package}.{name}": child[""]})
            else:
                out.append({name if prefix else f"{package}.{name}": build(child, f"{prefix}{name}.", sub)})
        return out

    return ["api/index.md", *build(tree, "", order)]


def on_config(config, **kwargs):
    spec = importlib.util.spec_from_file_location("_lm", ROOT / "tools" / "layer_metrics.py")
    lm = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(lm)
    nav = api_nav(api_pages(), list(lm.LAYERS))
    for i, entry in enumerate(config["nav"]):
        if isinstance(entry, dict) and SECTION in entry:
            config["nav"][i] = {SECTION: nav}
    return config


def on_files(files, config, **kwargs):
    from mkdocs.structure.files import File  # deferred: mkdocs is there only when the site is built

    for page, mod in api_pages().items():
        if files.get_file_from_path(page) is None:
            files.append(File.generated(config, page, content=page_text(page, mod)))
    return files
