"""Strict configuration: every table and key of a scene file or a study.toml is checked before any work.

Validation uses pydantic v2 models with ``extra="forbid"`` (an unknown table or
key is an error that lists the allowed ones) and strict leaf types of our
own (:data:`Number`, :data:`Integer`, :data:`Bool`, :data:`Text`, …): a TOML
value of the wrong type is refused, never converted (``first_only = "no"``,
``seed = true``, ``energy = "0.3"``). The models only *check*: the values the
code uses are the file's own, unchanged, so every scene keeps its
``result_hash()`` and runs on disk still resume.

A failure raises :class:`ConfigError` (a :class:`~hhscatter.scene.scene.ConfigError`:
the CLI prints it and exits with status 2, no traceback) with one line per
problem::

    studies/fig3/study.toml: [sections] first_only must be true or false, got 'no'
    studies/fig3/study.toml: unknown table [snapshot]; allowed tables: [about], [follow], …
    studies/fig3/study.toml: [study] unknown key 'n_bot'; allowed keys: boot_seed, fit_window, …

A study declares its ``[study]`` table as a :class:`StudyParams` subclass
named ``Params`` in its ``study.py``; its fields are the keys, with defaults
for the optional ones.
"""
from __future__ import annotations

import copy
import difflib
from functools import lru_cache
from typing import Annotated, Any

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    ValidationError,
    create_model,
    model_validator,
)

from hhscatter.errors import ConfigError

#: the initial-condition regions of a scene (hhscatter.scene.ics)
REGIONS = ("disk", "well", "square")

__all__ = [
    "Bool",
    "ConfigError",
    "Integer",
    "Integers",
    "Number",
    "NumberLists",
    "NumberOr",
    "NumberOrNumbers",
    "Numbers",
    "OneOf",
    "StudyParams",
    "Text",
    "Texts",
    "apply_convention",
    "validate_conventions_file",
    "validate_scene_file",
    "validate_study_file",
]




# -- strict leaf types (the raw value is kept, never converted) ----------------------------------
def _strict(what: str, ok) -> Any:
    def check(v):
        if not ok(v):
            raise ValueError(f"must be {what}")
        return v

    return Annotated[Any, AfterValidator(check)]


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _is_nums(v) -> bool:
    return isinstance(v, list) and all(_is_num(x) for x in v)


#: a TOML integer or float (not a boolean, not a string)
Number = _strict("a number", _is_num)
#: a TOML integer
Integer = _strict("an integer", lambda v: isinstance(v, int) and not isinstance(v, bool))
#: true or false
Bool = _strict("true or false", lambda v: isinstance(v, bool))
#: a string
Text = _strict("a string (in quotes)", lambda v: isinstance(v, str))
#: a list of numbers
Numbers = _strict("a list of numbers", _is_nums)
#: a list of integers
Integers = _strict("a list of integers",
                   lambda v: isinstance(v, list) and all(isinstance(x, int) and not isinstance(x, bool) for x in v))
#: a list of strings
Texts = _strict("a list of strings", lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v))
#: a list of lists of numbers (e.g. windows [[t_lo, t_hi], …])
NumberLists = _strict("a list of lists of numbers", lambda v: isinstance(v, list) and all(_is_nums(x) for x in v))
#: a number, or a list of numbers (a grid axis of a scene file)
NumberOrNumbers = _strict("a number or a list of numbers", lambda v: _is_num(v) or (_is_nums(v) and len(v) > 0))


def OneOf(*values) -> Any:
    """OneOf('a', 'b') -> a leaf type that accepts exactly these values."""
    return _strict("one of " + ", ".join(_show(v) for v in values), lambda v: any(v == x and type(v) is type(x)
                                                                               for x in values))


def NumberOr(*values) -> Any:
    """NumberOr('tau0') -> a number, or one of these values."""
    return _strict("a number or one of " + ", ".join(_show(v) for v in values),
                   lambda v: _is_num(v) or any(v == x and type(v) is type(x) for x in values))


class _Table(BaseModel):
    model_config = ConfigDict(extra="forbid")


# -- the tables of a scene ----------------------------------------------------------------------
class SectionsTable(_Table):
    """``[sections]``: which crossings of the section to record (hhscatter.scene.scene.SectionWindow)."""

    t_from: Number = None
    t_to: Number = None
    e_min: Number = None
    e_max: Number = None
    first_only: Bool = None
    stop: Bool = None


class SnapshotsTable(_Table):
    """``[snapshots]``: ``times = [...]`` or ``start``, ``stop``, ``step``."""

    times: Numbers = None
    start: Number = None
    stop: Number = None
    step: Number = None

    @model_validator(mode="after")
    def _one_form(self):
        given = [k for k in ("start", "stop", "step") if getattr(self, k) is not None]
        if self.times is not None and given:
            raise ValueError("takes 'times' or start, stop and step, not both")
        if self.times is None and len(given) != 3:
            raise ValueError("needs 'times' or all of start, stop and step")
        return self


class FollowTable(_Table):
    """``[follow]``: escaped orbits followed to r_far (conservative scenes), crossings of these radii recorded."""

    radii: Numbers


class SceneTable(_Table):
    """``[scene]`` of a scene file: the Scene fields (energy and gamma may be lists: a grid)."""

    energy: NumberOrNumbers = None
    gamma: NumberOrNumbers = None
    n: Integer = None
    seed: Integer = None
    region: OneOf(*REGIONS) = None
    radius: Number = None
    r_esc: Number = None
    r_far: Number = None
    t_max: Number = None
    tol: Number = None
    omega: Number = None
    lam: Number = None
    chunk_size: Integer = None
    batch_size: Integer = None
    ics: Text = None
    continue_settled: Bool = None
    name: Text = None


class StudySceneTable(SceneTable):
    """``[scene]`` of a study.toml: one scene's fields (no grid: a study makes its runs itself)."""

    energy: Number = None
    gamma: Number = None


class AboutTable(_Table):
    """``[about]`` of a study.toml (see hhscatter.studies.graph)."""

    title: Text = None
    paper: Text = None
    summary: Text = None
    setup: Text = None  # the study's own setup in a few words, when its ICs are not the [scene]'s region


class StudyParams(_Table):
    """Base of a study's ``Params``: the keys of its ``[study]`` table, strictly typed; no other key is allowed."""


_SCENE_TABLES = {"sections": SectionsTable, "snapshots": SnapshotsTable, "follow": FollowTable}


def _scene_file_model():
    fields = {"scene": (SceneTable, ...), **{k: (m, None) for k, m in _SCENE_TABLES.items()},
              "scale": (dict[str, SceneTable], None)}
    return create_model("SceneFile", __base__=_Table, **fields)


SceneFile = _scene_file_model()


@lru_cache(maxsize=None)
def _partial(model: type[BaseModel]) -> type[BaseModel]:
    """The model with every field optional (an override table: a scale's [study])."""
    fields = {name: (Annotated[(f.annotation, *f.metadata)] if f.metadata else f.annotation, None)
              for name, f in model.model_fields.items()}
    return create_model(f"{model.__name__}Override", __base__=_Table, **fields)


@lru_cache(maxsize=None)
def study_file_model(params: type[BaseModel] | None):
    """The model of a study.toml whose [study] table is ``params`` (None: any keys, unchecked)."""
    study = params if params is not None else dict[str, Any]
    override = _partial(params) if params is not None else dict[str, Any]
    tables = {k: (m, None) for k, m in _SCENE_TABLES.items()}
    scale = create_model("StudyScale", __base__=_Table, scene=(StudySceneTable, None),
                         **{k: (_partial(m) if m is not FollowTable else m, None) for k, m in _SCENE_TABLES.items()},
                         study=(override, None))
    return create_model("StudyFile", __base__=_Table, convention=(Text, None),
                        about=(AboutTable, None), needs=(dict[str, Text], None),
                        scene=(StudySceneTable, ...), **tables, study=(study, None if params is None else ...),
                        scale=(dict[str, scale], None))


# -- messages ------------------------------------------------------------------------------------
def _show(v) -> str:
    """A value as TOML writes it (true/false, quoted strings, [lists])."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, dict):
        return "a table"
    if isinstance(v, list):
        return "[" + ", ".join(_show(x) for x in v) + "]"
    return repr(v)


def _fields(node) -> list | None:
    """The keys a model (or dict[str, model] value) allows, or None for a leaf."""
    if isinstance(node, type) and issubclass(node, BaseModel):
        return list(node.model_fields)
    return None


def _child(node, key):
    """The annotation one level below ``node`` along ``key`` (models, dict values, list items)."""
    origin = getattr(node, "__origin__", None)
    if isinstance(node, type) and issubclass(node, BaseModel):
        f = node.model_fields.get(key)
        return None if f is None else f.annotation
    if origin is dict:
        return node.__args__[1]
    if origin is list:
        return node.__args__[0]
    return None


def _is_table(node) -> bool:
    return (isinstance(node, type) and issubclass(node, BaseModel)) or getattr(node, "__origin__", None) is dict


def _split(model, loc):
    """(table path, key path, node of the table) of an error location: tables nest through models and dicts."""
    node, table = model, []
    for i, part in enumerate(loc):
        nxt = _child(node, part)
        is_table = (isinstance(nxt, type) and issubclass(nxt, BaseModel)) or getattr(nxt, "__origin__", None) is dict
        if isinstance(part, int) or not is_table:
            return table, list(loc[i:]), node
        table.append(str(part))
        node = nxt
    return table, [], node


def _key_path(parts) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def did_you_mean(name, choices) -> str:
    """did_you_mean('summry', ['summary', 'title']) -> " (did you mean 'summary'?)", or "" if nothing is close."""
    close = difflib.get_close_matches(str(name), [str(c) for c in choices], n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _message(model, err: dict) -> str:
    loc = tuple(err["loc"])
    kind = err["type"]
    table, key, node = _split(model, loc)
    where = f"[{'.'.join(table)}]" if table else ""
    if kind == "extra_forbidden":
        allowed = _fields(node) or []
        if not table and len(key) == 1:
            tables = [k for k in allowed if _is_table(_child(node, k))]
            if isinstance(err.get("input"), dict) or not set(allowed) - set(tables):
                return (f"unknown table [{key[0]}]{did_you_mean(key[0], tables)}; allowed tables: "
                        + ", ".join(f"[{k}]" for k in sorted(tables)))
            return (f"unknown key {key[0]!r}{did_you_mean(key[0], set(allowed) - set(tables))} before the first "
                    "table; allowed keys there: "
                    + ", ".join(sorted(set(allowed) - set(tables))))
        return (f"{where} unknown key {_key_path(key)!r}{did_you_mean(key[-1], allowed)}; "
                f"allowed keys: {', '.join(sorted(allowed))}").strip()
    if kind == "missing":
        return f"{where} needs {_key_path(key)!r}" if key else f"needs a {where} table"
    if kind in ("model_type", "dict_type"):
        return f"{where} must be a table, got {_show(err.get('input'))}"
    if kind == "list_type":
        return f"{where} {_key_path(key)} must be a list, got {_show(err.get('input'))}".strip()
    if kind == "value_error":
        msg = str(err.get("ctx", {}).get("error", err.get("msg")))
        if not key:  # a check of the whole table (e.g. [snapshots])
            return f"{where} {msg}"
        return f"{where} {_key_path(key)} {msg}, got {_show(err.get('input'))}".strip()
    return f"{where} {_key_path(key)}: {err.get('msg')}".strip()


def _validate(model, doc: dict, source: str, suffix: str = "") -> None:
    try:
        model.model_validate(doc)
    except ValidationError as exc:
        lines = [f"{source}: {_message(model, e)}{suffix}" for e in exc.errors()]
        raise ConfigError("\n".join(lines)) from None


def merge_tables(base: dict, over: dict) -> dict:
    """merge_tables(base, over) -> a copy of ``base`` with the (nested) tables of ``over`` laid over it: how a
    ``[scale.<s>]`` table overrides a study.toml."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = merge_tables(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def validate_scene_file(doc: dict, source: str) -> None:
    """validate_scene_file(doc, source) -> None or ConfigError: a scene file's tables, keys and value types.

    Each ``[scale.<name>]`` table holds overrides of ``[scene]`` keys.
    """
    _validate(SceneFile, doc, str(source))


def validate_study_file(doc: dict, source: str, params: type[BaseModel] | None = None) -> None:
    """validate_study_file(doc, source, params=None) -> None or ConfigError: a study.toml, every scale of it.

    ``params``: the study's ``Params`` model of its ``[study]`` table. The file
    is checked as written (every table, every ``[scale.<s>.…]`` override) and
    then once per scale with the overrides applied (a key the scale needs must
    be there).
    """
    model = study_file_model(params)
    _validate(model, doc, str(source))
    base = {k: v for k, v in doc.items() if k != "scale"}
    for name, over in (doc.get("scale") or {}).items():
        _validate(model, merge_tables(base, over), str(source), f" (at scale {name!r})")


# -- conventions: scene keys declared once (studies/conventions.toml), inherited by `convention = "<name>"` ------
def validate_conventions_file(doc: dict, source: str) -> None:
    """validate_conventions_file(doc, source) -> None or ConfigError: each table ``[<name>]`` of the conventions
    file holds ``[scene]`` keys of a study (strictly typed, no other key)."""
    model = create_model("ConventionsFile", __base__=_Table,
                         **{str(k): (StudySceneTable, None) for k in doc})
    _validate(model, doc, str(source))


def apply_convention(doc: dict, conventions: dict, source: str, conventions_source: str) -> dict:
    """apply_convention(doc, conventions, source, conventions_source) -> the study file ``doc`` with the scene
    keys of its ``convention`` laid under its own ``[scene]`` (a copy; ``doc`` unchanged).

    A study without ``convention`` is returned as it is. An unknown convention
    name, or a study that sets again, in ``[scene]`` or in a scale's
    ``[scale.<s>.scene]``, a key its convention provides (the convention is
    the one place of it, so it cannot drift), is a :class:`ConfigError`.
    """
    name = doc.get("convention")
    if name is None:
        return copy.deepcopy(doc)
    if name not in conventions:
        raise ConfigError(f"{source}: unknown convention {name!r}; conventions in {conventions_source}: "
                          + ", ".join(repr(k) for k in sorted(conventions)))
    given = dict(conventions[name])
    clashes = [f"[scene] {k}" for k in doc.get("scene", {}) if k in given]
    for s, over in (doc.get("scale") or {}).items():
        clashes += [f"[scale.{s}.scene] {k}" for k in (over.get("scene") or {}) if k in given]
    if clashes:
        raise ConfigError("\n".join(f"{source}: {c} is set by convention {name!r} ({conventions_source}); "
                                     f"remove it here" for c in clashes))
    out = copy.deepcopy(doc)
    out["scene"] = {**copy.deepcopy(given), **out.get("scene", {})}
    return out
