"""The installed distribution's version (``pyproject.toml`` is its only source), recorded in every table's metadata,
and the engine's revision: which integration code made a run's tables.

A scene's ``result_hash`` names the scene; two engines can integrate one scene to different tables (another event
rule, step control, initial-condition sampling). ``ENGINE_REVISION`` counts the changes of the engine that can
change a table: from revision 2 on it enters every scene's ``result_hash``, so that a run made by another revision
is not resumed or kept as if it were this one (:meth:`hhscatter.scene.scene.Scene.result_hash`; a resume refuses
it and a study makes it again). Revision 1 is the engine of the first release that records it, and leaves the
hashes of the scenes before it as they were.

``ENGINE_SOURCES`` are the modules whose code decides the tables (docstrings and comments aside), and
``ENGINE_SOURCES_SHA256`` the hash of their code as of this revision (:func:`engine_sources_sha256`): the test
suite compares the two, so that a change of the engine's code is a decision, recorded here — a new revision where
a table can change, or only the new hash where none can (a rename, a refactor with the same arithmetic).

Examples
--------
>>> ENGINE_REVISION >= 1 and len(engine_sources_sha256()) == 64
True
"""

from importlib.metadata import PackageNotFoundError, version

__all__ = ["ENGINE_REVISION", "ENGINE_SOURCES", "ENGINE_SOURCES_SHA256", "__version__", "engine_sources_sha256"]

try:
    __version__ = version("hhscatter")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
del version, PackageNotFoundError

#: the engine's revision (see the module's notes): bump it with any change that can change a table
ENGINE_REVISION = 1

#: the modules, relative to the package, whose code decides the tables (every .py of a folder given)
ENGINE_SOURCES = ("integrate", "model", "scene/ics.py", "outcomes.py", "run/worker.py")

#: engine_sources_sha256() as of ENGINE_REVISION (recorded by hand with each change of those modules)
ENGINE_SOURCES_SHA256 = "d364e22f11cf8e13ef4d21fc9ed7cef08a6b888cc7ed9b4b01ed68963f4bc06e"


def _code(tree) -> str:
    """The module's code without docstrings, as ast.dump gives it (comments are not in the tree)."""
    import ast  # deferred: only the check of the record needs it

    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if (
            isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
            and body
            and isinstance(body[0], ast.Expr)
            and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str)
        ):
            node.body = body[1:] or [ast.Pass()]
    return ast.dump(tree, annotate_fields=False)


def engine_sources_sha256() -> str:
    """engine_sources_sha256() -> sha256 (hex) of the code of :data:`ENGINE_SOURCES`, docstrings and comments left
    out, the files in sorted order by their path in the package."""
    import ast  # deferred: only the check of the record needs it
    import hashlib  # deferred: as ast
    from pathlib import Path  # deferred: as ast

    root = Path(__file__).resolve().parent
    files = []
    for rel in ENGINE_SOURCES:
        p = root / rel
        files += sorted(p.rglob("*.py")) if p.is_dir() else [p]
    h = hashlib.sha256()
    for f in sorted(files, key=lambda f: f.relative_to(root).as_posix()):
        h.update(f.relative_to(root).as_posix().encode() + b"\0")
        h.update(_code(ast.parse(f.read_text(encoding="utf-8"))).encode() + b"\0")
    return h.hexdigest()
