"""Griffe extension for the API reference: make the plain-prose docstrings read as Markdown.

The package's docstrings are plain prose written for ``help()``; rendered as
Markdown three things went wrong, and this extension rewrites them:

* Sphinx roles (``:func:`survival_curve```, ``:mod:`hhscatter.data.tables```):
  Markdown has no roles, so they become inline code. Names are not turned
  into links: an unresolvable cross-reference would be a warning, and the
  docs build is strict.
* A ``*`` that is part of a symbol (τ*, f*, t*) opened an emphasis that ate
  the text up to the next one: such stars are escaped.
* Field lists of dataclasses and parameters (a name, two or more spaces, its
  description, continuation lines indented further) ran together into one
  paragraph: they become bullet lists.
* Bullet lists written with ``*`` showed their stars as text, run into the
  paragraph before them: they become Markdown lists (``bullet_lists``).

The docstrings' numpy sections (Parameters, Returns, Examples) are parsed by
griffe (``docstring_style: numpy`` in mkdocs.yml).
"""

from __future__ import annotations

import re

import griffe

_ROLE = re.compile(r":(?:py:)?(?:func|meth|class|mod|attr|obj|data|exc|const|term):`(~?)([^`]+)`")


def roles_to_code(text: str) -> str:
    """roles_to_code(text) -> text with every ``:role:`name``` replaced by ```name```.

    As in Sphinx, ``:role:`~a.b.c``` shows only the last component, ```c```.
    """
    return _ROLE.sub(lambda m: f"`{m.group(2).rsplit('.', 1)[-1] if m.group(1) else m.group(2)}`", text)


_CODE_SPAN = re.compile(r"(`+[^`]*`+)")


def _escape_stars_in(text: str, state: list) -> str:
    """Escape the stars of one code-free piece of a line; ``state[0]`` is True inside an emphasis."""
    out, i = [], 0
    while i < len(text):
        c = text[i]
        if c != "*":
            out.append(c)
            i += 1
            continue
        if text.startswith("**", i):
            out.append("**")
            i += 2
            continue
        before = text[i - 1] if i else " "
        after = text[i + 1] if i + 1 < len(text) else " "
        if not state[0] and (before.isspace() or before in "([{\"'") and not after.isspace():
            state[0] = True  # opens an emphasis: *word
            out.append(c)
        elif state[0] and not before.isspace():
            state[0] = False  # closes it: word*
            out.append(c)
        else:
            out.append("\\*")  # a literal star: τ*, f*, 2 * x
        i += 1
    return "".join(out)


def escape_literal_stars(text: str) -> str:
    """escape_literal_stars(text) -> text with symbol stars (τ*, t*) escaped; *emphasis* and code kept."""
    lines, fenced, prev_code = [], False, False
    for line in text.split("\n"):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        indented = line.startswith("    ") and (prev_code or not lines or not lines[-1].strip())
        prev_code = indented or (prev_code and not line.strip())
        if fenced or indented or line.lstrip().startswith("```"):
            lines.append(line)
            continue
        state = [False]
        lines.append("".join(p if i % 2 else _escape_stars_in(p, state) for i, p in enumerate(_CODE_SPAN.split(line))))
    return "\n".join(lines)


_FIELD = re.compile(r"^( {0,3})([A-Za-z_][\w.]*(?:\s*,\s*[A-Za-z_][\w.]*)*)\s{2,}(\S.*)$")


def field_lists(text: str) -> str:
    """field_lists(text) -> text whose 'name   description' blocks are Markdown bullet lists.

    A block is a run of lines, the first of which is ``name  description``
    (name: identifiers separated by commas, then 2+ spaces), every other
    either another such line at the same indentation or a continuation
    indented deeper than the name. At least two entries make a list.
    """
    lines = text.split("\n")
    out, i = [], 0
    while i < len(lines):
        m = _FIELD.match(lines[i])
        if not m:
            out.append(lines[i])
            i += 1
            continue
        indent = len(m.group(1))
        entries, j = [], i
        while j < len(lines):
            mm = _FIELD.match(lines[j])
            if mm and len(mm.group(1)) == indent:
                entries.append([mm.group(2), mm.group(3)])
            elif entries and lines[j].strip() and len(lines[j]) - len(lines[j].lstrip()) > indent + 2:
                entries[-1][1] += " " + lines[j].strip()
            else:
                break
            j += 1
        if len(entries) < 2:
            out.append(lines[i])
            i += 1
            continue
        if out and out[-1].strip():
            out.append("")
        for names, desc in entries:
            code = ", ".join(f"`{n.strip()}`" for n in names.split(","))
            out.append(f"- {code}: {desc}")
        out.append("")
        i = j
    return "\n".join(out)


_BULLET = re.compile(r"^(\s*)[*•] (?=\S)")


def bullet_lists(text: str) -> str:
    """bullet_lists(text) -> text whose ``* item`` lines are Markdown list items (``- item``), each list set off
    from the paragraph before it by a blank line (Python-Markdown starts no list inside a paragraph).

    The docstrings write lists with ``*`` for ``help()``; left as they were, the star escaping below saw a
    literal star and the page showed ``* item`` run into the paragraph. Code (fenced or indented) is untouched.
    """
    out, fenced, prev_bullet = [], False, False
    for line in text.split("\n"):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        m = None if fenced else _BULLET.match(line)
        if m and len(m.group(1)) < 4:
            if out and out[-1].strip() and not prev_bullet:
                out.append("")
            line = f"{m.group(1)}- {line[m.end() :]}"
            prev_bullet = True
        elif not line.strip() or not line.startswith(" "):
            prev_bullet = prev_bullet and line.startswith(" ")
        out.append(line)
    return "\n".join(out)


_DOCTEST = re.compile(r"^[ \t]*>>>")


def _prose_and_doctests(text: str) -> list[tuple[bool, str]]:
    """[(is a doctest, lines)]: a doctest runs from a ``>>>`` line to the next blank line (its output included).

    The Examples sections of numpy docstrings are not indented, so the rewrites below would take them for prose
    (``4 * err`` showed as ``4 \\* err`` on the page, the code block is shown verbatim).
    """
    blocks: list[tuple[bool, list[str]]] = []
    for line in text.split("\n"):
        doctest = bool(_DOCTEST.match(line)) or bool(blocks and blocks[-1][0] and line.strip())
        if blocks and blocks[-1][0] == doctest:
            blocks[-1][1].append(line)
        else:
            blocks.append((doctest, [line]))
    return [(d, "\n".join(lines)) for d, lines in blocks]


def scripts(text: str) -> str:
    """scripts(text) -> ``x^{a}`` and ``x_{a}`` of the prose as ``x<sup>a</sup>``, ``x<sub>a</sub>`` (code spans
    kept): plain-text formulas such as ``E0 e^{−μγt}`` read in ``help()`` and show as formulas on the page, and
    Markdown no longer takes the underscores of ``∫_{E_c}^{E0}`` for emphasis."""
    from hhscatter.publish.formatting import scripts_to_html

    return "".join(p if p.startswith("`") else scripts_to_html(p) for p in _CODE_SPAN.split(text))


def clean_docstring(text: str) -> str:
    """The rewrites of the module doc, in order: roles to code, bullet lists, scripts, literal stars, field lists.

    Doctest blocks (``>>>`` lines and their output) are code and kept as they are.
    """
    return "\n".join(
        block if doctest else field_lists(escape_literal_stars(scripts(bullet_lists(roles_to_code(block)))))
        for doctest, block in _prose_and_doctests(text)
    )


class SphinxRolesToCode(griffe.Extension):
    """Rewrite every docstring: Sphinx roles to inline code, literal stars escaped, field lists as lists."""

    def on_instance(self, *, obj, **kwargs) -> None:  # noqa: D102 - griffe hook
        if obj.docstring is not None:
            obj.docstring.value = clean_docstring(obj.docstring.value)
