"""Griffe extension for the API reference: render Sphinx roles as inline code.

The package's docstrings are plain prose that sometimes names other objects
with Sphinx roles (``:func:`survival_curve```, ``:mod:`hhscatter.tables```).
Markdown has no roles, so mkdocstrings would print the role markup literally;
this extension rewrites them to inline code. Names are not turned into links:
an unresolvable cross-reference would be a warning, and the docs build is
strict.
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


class SphinxRolesToCode(griffe.Extension):
    """Rewrite Sphinx roles in every docstring to Markdown inline code."""

    def on_instance(self, *, obj, **kwargs) -> None:  # noqa: D102 - griffe hook
        if obj.docstring is not None:
            obj.docstring.value = roles_to_code(obj.docstring.value)
