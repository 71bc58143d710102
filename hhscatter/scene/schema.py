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

A ``[study]`` table is checked against a model of its keys (a study's ``Params``, a pydantic model of the leaf
types below); its fields are the keys, with defaults for the optional ones.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import os
import tomllib
from functools import cache
from pathlib import Path
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
from hhscatter.model import DISSIPATIONS
from hhscatter.scene.scene import MOMENTA, REGIONS, Follow, Noise, Scene, SectionWindow, scene_from_dict

__all__ = [
    "load_scene",
    "scene_dict_from_toml",
    "table_of",
    "typed_params",
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
    "Text",
    "Texts",
    "apply_convention",
    "validate_conventions_file",
    "validate_scene_file",
    "validate_study_file",
]


# -- strict leaf types ------------------------------------------------------------------------------
# A file is checked as written: the raw value is kept (a TOML 1 stays an int where a number is allowed), so that
# messages and records show what the file says. Each leaf type also declares what the value means in Python
# (Number -> float, Integer -> int, Numbers -> list of floats, ...): typed_params() converts a study's [study]
# table with it, so study code receives typed values and never casts.
class _Convert:
    """The Python type of a leaf (metadata of its Annotated type; read by :func:`typed_params`)."""

    __slots__ = ("to",)

    def __init__(self, to):
        self.to = to


def _strict(what: str, ok, to=None) -> Any:
    def check(v):
        if not ok(v):
            raise ValueError(f"must be {what}")
        return v

    return Annotated[Any, AfterValidator(check), _Convert(to)]


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _is_nums(v) -> bool:
    return isinstance(v, list) and all(_is_num(x) for x in v)


def _floats(v) -> list:
    return [float(x) for x in v]


#: a TOML integer or float (not a boolean, not a string); in Python a float
Number = _strict("a number", _is_num, float)
#: a TOML integer; in Python an int
Integer = _strict("an integer", lambda v: isinstance(v, int) and not isinstance(v, bool), int)
#: true or false
Bool = _strict("true or false", lambda v: isinstance(v, bool), bool)
#: a string
Text = _strict("a string (in quotes)", lambda v: isinstance(v, str), str)
#: a list of numbers; in Python a list of floats
Numbers = _strict("a list of numbers", _is_nums, _floats)
#: a list of integers
Integers = _strict(
    "a list of integers",
    lambda v: isinstance(v, list) and all(isinstance(x, int) and not isinstance(x, bool) for x in v),
    lambda v: [int(x) for x in v],
)
#: a list of strings
Texts = _strict("a list of strings", lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v), list)
#: a list of lists of numbers (e.g. windows [[t_lo, t_hi], …]); in Python a list of lists of floats
NumberLists = _strict(
    "a list of lists of numbers",
    lambda v: isinstance(v, list) and all(_is_nums(x) for x in v),
    lambda v: [_floats(x) for x in v],
)
#: a number, or a list of numbers (a grid axis of a scene file); in Python a float or a list of floats
NumberOrNumbers = _strict(
    "a number or a list of numbers",
    lambda v: _is_num(v) or (_is_nums(v) and len(v) > 0),
    lambda v: _floats(v) if isinstance(v, list) else float(v),
)


def _number_or_keep(v):
    return float(v) if _is_num(v) else v


def _show(v) -> str:
    """A value as TOML writes it (true/false, quoted strings, [lists])."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, dict):
        return "a table"
    if isinstance(v, list):
        return "[" + ", ".join(_show(x) for x in v) + "]"
    return repr(v)


def OneOf(*values) -> Any:
    """OneOf('a', 'b') -> a leaf type that accepts exactly these values."""
    return _strict(
        "one of " + ", ".join(_show(v) for v in values), lambda v: any(v == x and type(v) is type(x) for x in values)
    )  # kept as is


def NumberOr(*values) -> Any:
    """NumberOr('tau0') -> a number, or one of these values."""
    return _strict(
        "a number or one of " + ", ".join(_show(v) for v in values),
        lambda v: _is_num(v) or any(v == x and type(v) is type(x) for x in values),
        _number_or_keep,
    )


class _Table(BaseModel):
    model_config = ConfigDict(extra="forbid")


# -- the tables of a scene: derived from the dataclasses (one declaration of every field) -----------
#: the leaf type of a file value, by the dataclass annotation of its field
_LEAF_OF = {
    "float": Number,
    "float | None": Number,
    "int": Integer,
    "int | None": Integer,
    "bool": Bool,
    "str": Text,
    "str | None": Text,
    "tuple": Numbers,
}


def table_of(cls, name: str, doc: str, *, leaves: dict | None = None, exclude=(), required=()) -> type[BaseModel]:
    """table_of(dataclass, name, doc) -> the strict model of its file table: one key per dataclass field.

    Each field's leaf type follows from its annotation (``float`` → :data:`Number`, ``int`` → :data:`Integer`,
    ``bool`` → :data:`Bool`, ``str`` → :data:`Text`, ``tuple`` → :data:`Numbers`); ``leaves`` overrides it
    per field (e.g. a list of energies: a grid). Keys are optional unless in ``required`` (the dataclass
    applies its own defaults and range checks when the Scene is built). An annotation without a leaf type is an
    error at import: a new field must say how a file writes it.
    """
    leaves = leaves or {}
    fields = {}
    for f in dataclasses.fields(cls):
        if f.name in exclude or not f.init:
            continue
        leaf = leaves.get(f.name) or _LEAF_OF.get(str(f.type))
        if leaf is None:
            raise TypeError(
                f"{cls.__name__}.{f.name}: no file type for annotation {f.type!r} (add it to _LEAF_OF or pass leaves=)"
            )
        fields[f.name] = (leaf, ... if f.name in required else None)
    return create_model(name, __base__=_Table, __doc__=doc, **fields)


SectionsTable = table_of(
    SectionWindow, "SectionsTable", "``[sections]``: which crossings of the section to record (SectionWindow's fields)."
)
FollowTable = table_of(
    Follow,
    "FollowTable",
    "``[follow]``: escaped orbits followed to r_far (conservative "
    "scenes), crossings of these radii recorded (Follow's fields).",
    required=("radii",),
)
NoiseTable = table_of(
    Noise,
    "NoiseTable",
    "``[noise]``: random forces on the momenta: a heat bath (temperature, with drag) or a noise strength "
    "(sigma, without drag), the kick interval and the flow between the kicks (Noise's fields).",
)
SceneTable = table_of(
    Scene,
    "SceneTable",
    "``[scene]`` of a scene file: the Scene fields (energy and gamma may be lists: a grid).",
    exclude=("sections", "snapshots", "follow", "noise", "system"),
    leaves={
        "energy": NumberOrNumbers,
        "gamma": NumberOrNumbers,
        "region": OneOf(*REGIONS),
        "momentum": OneOf(*MOMENTA),
    },
)


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


StudySceneTable = table_of(
    Scene,
    "StudySceneTable",
    "``[scene]`` of a study.toml: one scene's fields (no grid: a study makes its runs itself).",
    exclude=("sections", "snapshots", "follow", "noise", "system"),
    leaves={"region": OneOf(*REGIONS), "momentum": OneOf(*MOMENTA)},
)


class SystemTable(_Table):
    """``[system]``: the system as data (:mod:`hhscatter.model.spec`): a built-in ``name`` or a ``potential``
    in x, y, its ``[system.params]``, the ``dissipation`` law, and overrides of derived quantities."""

    name: Text = None
    potential: Text = None
    dissipation: OneOf(*DISSIPATIONS) = None
    params: dict[str, Number] = None
    critical_energy: Number = None
    omega_radius: Number = None
    exits: NumberLists = None


class AboutTable(_Table):
    """``[about]`` of a study.toml (see hhscatter.studies.graph)."""

    title: Text = None
    paper: Text = None
    summary: Text = None
    setup: Text = None  # the study's own setup in a few words, when its ICs are not the [scene]'s region


def typed_params(model: type[BaseModel], raw: dict) -> BaseModel:
    """typed_params(Params, raw) -> a ``Params`` instance: each key of ``raw`` (a checked ``[study]`` table), or the
    field's default, converted to the Python type its leaf type declares. ``raw`` must have passed the file check
    (:func:`validate_study_file`); a required key missing from it is a :class:`ConfigError`.

    Examples
    --------
    >>> from pydantic import BaseModel
    >>> from hhscatter.scene.schema import Integer, Numbers, typed_params
    >>> class Params(BaseModel):
    ...     energies: Numbers
    ...     n: Integer = 10
    >>> p = typed_params(Params, {"energies": [0.3, 1]})
    >>> p.energies, p.n
    ([0.3, 1.0], 10)
    """
    return model.model_construct(**{name: typed_value(model, name, raw) for name in model.model_fields})


def typed_value(model: type[BaseModel], name: str, raw: dict) -> Any:
    """typed_value(Params, name, raw) -> the one key ``name`` of :func:`typed_params`: ``raw[name]`` or the field's
    default, converted to its declared Python type (KeyError if ``Params`` does not declare ``name``)."""
    f = model.model_fields[name]
    if name in raw:
        v = raw[name]
    elif not f.is_required():
        v = copy.deepcopy(f.default)
    else:
        raise ConfigError(f"[study] needs {name!r} ({model.__name__} declares it without a default)")
    conv = next((m.to for m in f.metadata if isinstance(m, _Convert)), None)
    return conv(v) if conv is not None and v is not None else v


_SCENE_TABLES = {
    "sections": SectionsTable,
    "snapshots": SnapshotsTable,
    "follow": FollowTable,
    "noise": NoiseTable,
    "system": SystemTable,
}


def _scene_file_model():
    fields = {
        "scene": (SceneTable, ...),
        **{k: (m, None) for k, m in _SCENE_TABLES.items()},
        "scale": (dict[str, SceneTable], None),
    }
    return create_model("SceneFile", __base__=_Table, **fields)


SceneFile = _scene_file_model()


@cache
def _partial(model: type[BaseModel]) -> type[BaseModel]:
    """The model with every field optional (an override table: a scale's [study])."""
    fields = {
        name: (Annotated[(f.annotation, *f.metadata)] if f.metadata else f.annotation, None)
        for name, f in model.model_fields.items()
    }
    return create_model(f"{model.__name__}Override", __base__=_Table, **fields)


@cache
def study_file_model(params: type[BaseModel] | None):
    """The model of a study.toml whose [study] table is ``params`` (None: any keys, unchecked)."""
    study = params if params is not None else dict[str, Any]
    override = _partial(params) if params is not None else dict[str, Any]
    tables = {k: (m, None) for k, m in _SCENE_TABLES.items()}
    scale = create_model(
        "StudyScale",
        __base__=_Table,
        scene=(StudySceneTable, None),
        **{k: (_partial(m) if m is not FollowTable else m, None) for k, m in _SCENE_TABLES.items()},
        study=(override, None),
    )
    return create_model(
        "StudyFile",
        __base__=_Table,
        convention=(Text, None),
        about=(AboutTable, None),
        needs=(dict[str, Text], None),
        scene=(StudySceneTable, ...),
        **tables,
        study=(study, None if params is None else ...),
        scale=(dict[str, scale], None),
    )


# -- messages ------------------------------------------------------------------------------------
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
                return f"unknown table [{key[0]}]{did_you_mean(key[0], tables)}; allowed tables: " + ", ".join(
                    f"[{k}]" for k in sorted(tables)
                )
            return (
                f"unknown key {key[0]!r}{did_you_mean(key[0], set(allowed) - set(tables))} before the first "
                "table; allowed keys there: " + ", ".join(sorted(set(allowed) - set(tables)))
            )
        return (
            f"{where} unknown key {_key_path(key)!r}{did_you_mean(key[-1], allowed)}; "
            f"allowed keys: {', '.join(sorted(allowed))}"
        ).strip()
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
    model = create_model("ConventionsFile", __base__=_Table, **{str(k): (StudySceneTable, None) for k in doc})
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
        raise ConfigError(
            f"{source}: unknown convention {name!r}; conventions in {conventions_source}: "
            + ", ".join(repr(k) for k in sorted(conventions))
        )
    given = dict(conventions[name])
    clashes = [f"[scene] {k}" for k in doc.get("scene", {}) if k in given]
    for s, over in (doc.get("scale") or {}).items():
        clashes += [f"[scale.{s}.scene] {k}" for k in (over.get("scene") or {}) if k in given]
    if clashes:
        raise ConfigError(
            "\n".join(
                f"{source}: {c} is set by convention {name!r} ({conventions_source}); remove it here" for c in clashes
            )
        )
    out = copy.deepcopy(doc)
    out["scene"] = {**copy.deepcopy(given), **out.get("scene", {})}
    return out


# -- scene files -> Scene --------------------------------------------------------------------------
def scene_dict_from_toml(path, scale: str | None = None, **overrides) -> dict:
    """scene_dict_from_toml(path, scale=None, **overrides) -> the raw scene dict of a TOML file.

    What :func:`load_scene` validates; values may still be lists (a grid, see
    :mod:`hhscatter.scene.grid`). A relative ``ics`` path in the file is relative to the file's folder (made
    absolute here); one given in ``overrides`` is taken as given.
    """
    path = Path(path)
    if path.is_dir():
        raise ConfigError(
            f"{path} is a folder: give a scene TOML file (a run directory is read with hhscatter.read_lifetimes and the other readers)"
        )
    try:
        doc = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ConfigError(f"scene file not found: {path}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"scene file {path} is not valid TOML: {exc}") from None
    if "scene" not in doc:
        raise ConfigError(f"scene file {path} has no [scene] table")
    validate_scene_file(doc, str(path))  # every table, key and type, before any work
    d = dict(doc["scene"])
    d.setdefault("name", path.parent.name)
    if "sections" in doc:
        d["sections"] = doc["sections"]
    if "snapshots" in doc:
        d["snapshots"] = doc["snapshots"]
    for table in ("follow", "noise", "system"):
        if table in doc:
            d[table] = doc[table]
    if scale is not None and scale != "quick":
        scales = doc.get("scale", {})
        if scale not in scales:
            raise ConfigError(f"scale must be one of {['quick', *scales]}, got {scale!r}")
        d.update(scales[scale])
    if isinstance(d.get("ics"), str) and d["ics"].strip() and not os.path.isabs(d["ics"]):
        d["ics"] = os.path.abspath(path.parent / d["ics"])  # the file's own paths are relative to its folder
    d.update({k: v for k, v in overrides.items() if v is not None})
    return d


def load_scene(path: str | os.PathLike[str], scale: str | None = None, **overrides: object) -> Scene:
    """A Scene from a TOML file.

    Layout: ``[scene]`` (Scene fields), optional ``[sections]`` (SectionWindow fields), ``[snapshots]``
    (``times = [...]`` or ``start/stop/step``), ``[noise]`` (Noise fields) and ``[scale.<name>]`` tables whose keys override
    ``[scene]`` when ``scale`` is given. A file whose ``energy`` or ``gamma`` is a list is a grid: load it
    with :func:`hhscatter.load_run`.

    Parameters
    ----------
    path : path
        The TOML file.
    scale : str, optional
        Name of a ``[scale.<name>]`` table to apply.
    **overrides
        Scene fields applied last.

    Returns
    -------
    Scene

    Raises
    ------
    ConfigError
        An unknown table or key (with a did-you-mean), a value out of range, or a grid file.

    Examples
    --------
    >>> import pathlib, tempfile, hhscatter
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "scene.toml"
    >>> _ = f.write_text("[scene]\\nenergy = 0.3\\nn = 1000\\n[scale.paper]\\nn = 10000000\\n")
    >>> hhscatter.load_scene(f).n, hhscatter.load_scene(f, "paper").n, hhscatter.load_scene(f, n=5).n
    (1000, 10000000, 5)
    """
    d = scene_dict_from_toml(path, scale, **overrides)
    for k in ("energy", "gamma"):
        if isinstance(d.get(k), (list, tuple)):
            raise ConfigError(
                f"{k} is a list in {path}: that is a grid run; load it with hhscatter.scene.grid.load_run"
            )
    return scene_from_dict(d)
