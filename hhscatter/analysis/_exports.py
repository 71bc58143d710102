"""Exports loaded on first use: the ``__getattr__`` and ``__dir__`` of a package whose public names live in its
modules (``from hhscatter.analysis.survival import survival_curve`` imports only the module that defines it)."""

import importlib
import sys


def lazy_exports(package: str, exports: dict):
    """The ``__getattr__`` and ``__dir__`` of ``package`` for ``exports`` {name: module of the package}.

    Examples
    --------
    >>> getattr_, dir_ = lazy_exports("hhscatter.analysis.stats", {"wilson_interval": "intervals"})
    >>> getattr_("wilson_interval").__name__
    'wilson_interval'
    """

    def __getattr__(name):
        if name in exports:
            return getattr(importlib.import_module(f"{package}.{exports[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(exports))

    return __getattr__, __dir__
