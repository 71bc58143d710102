"""Exports loaded on first use, generated from the code: the ``_EXPORTS``, ``__getattr__`` and ``__dir__`` of a
package whose public names live in its modules (``from hhscatter.analysis.survival import survival_curve``
imports only the module that defines it).

A package exports every public name its modules define at their top level (a function, a class, a constant: a
name without a leading underscore), read from their source with :mod:`ast` (nothing is imported to build the
map); a name that is also a module's name (``escape_rate.escape_rate``) stays the module's. A new estimator is
exported by defining it.
"""

import ast
import importlib
import sys
from pathlib import Path


def defined_names(source: str) -> list[str]:
    """The public names a module's ``source`` defines at its top level (functions, classes, assignments), in order.

    Examples
    --------
    >>> defined_names("import math\\nK = 2\\n_HIDDEN = 1\\ndef rate(t): ...\\nclass Fit: ...")
    ['K', 'rate', 'Fit']
    """
    names = []
    for node in ast.parse(source).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.append(node.name)
        elif isinstance(node, ast.Assign):
            names += [t.id for t in node.targets if isinstance(t, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.append(node.target.id)
    return [n for n in names if not n.startswith("_")]


def module_exports(folder: Path) -> dict[str, str]:
    """{public name: module} of the package in ``folder``: every public name its modules define.

    Raises ``ValueError`` when two modules define the same public name (the package could export only one).

    Examples
    --------
    >>> import hhscatter.analysis.stats as stats
    >>> module_exports(Path(stats.__file__).parent)["wilson_interval"]
    'intervals'
    """
    modules = sorted(f for f in Path(folder).glob("*.py") if not f.name.startswith("_"))
    stems = {f.stem for f in modules}
    out: dict[str, str] = {}
    for f in modules:
        for name in defined_names(f.read_text(encoding="utf-8")):
            if name in stems:
                continue
            if name in out and out[name] != f.stem:
                raise ValueError(f"{name!r} is defined by two modules of {folder}: {out[name]} and {f.stem}")
            out[name] = f.stem
    return dict(sorted(out.items()))


def lazy_exports(package: str, exports: dict | None = None):
    """The ``_EXPORTS``, ``__getattr__`` and ``__dir__`` of ``package``: ``exports`` {name: module of the
    package}, by default :func:`module_exports` of the package's folder.

    Examples
    --------
    >>> exports, getattr_, dir_ = lazy_exports("hhscatter.analysis.stats")
    >>> exports["wilson_interval"], getattr_("wilson_interval").__name__
    ('intervals', 'wilson_interval')
    """
    if exports is None:
        exports = module_exports(Path(sys.modules[package].__file__).parent)

    def __getattr__(name):
        if name in exports:
            return getattr(importlib.import_module(f"{package}.{exports[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(exports))

    return exports, __getattr__, __dir__
