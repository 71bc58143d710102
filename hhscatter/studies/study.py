"""A study: its folder, its study.toml (validated, with its scale and convention applied) and its outputs.

:class:`Study` is what a study's stages receive; :func:`load_study` makes it. The stage runner is
:func:`hhscatter.studies.run_stage`.
"""

from __future__ import annotations

import copy
import importlib.util
import json
import os
import sys
import tomllib
import types
from dataclasses import dataclass, field
from pathlib import Path

from hhscatter.analysis.stats.library_warnings import warning_counts
from hhscatter.data.schema import provenance
from hhscatter.data.write import write_part, write_parts_streamed
from hhscatter.errors import ConfigError, StudyError
from hhscatter.model import HenonHeiles, System
from hhscatter.model.spec import system_from_spec
from hhscatter.reproduction.verdicts import (
    NO_VERDICT,
    REFERENCE_KINDS,
    SMOKE_SCALES,
    row_bound,
    row_verdict,
    without_verdicts,
)
from hhscatter.run.plan import SCENE_FILE
from hhscatter.run.runner import simulate
from hhscatter.scene.scene import Scene, scene_from_dict
from hhscatter.scene.schema import (
    apply_convention,
    did_you_mean,
    merge_tables,
    typed_params,
    typed_value,
    validate_conventions_file,
    validate_study_file,
)
from hhscatter.studies.graph import (
    HEADER_TABLES,
    GraphError,
    StudyInfo,
    studies,
    study_info,
)
from hhscatter.studies.graph import default_root as _graph_default_root
from hhscatter.studies.jsonio import _jsonable, write_json_atomic
from hhscatter.studies.provenance import made_from, sealed, verify_numbers

STAGES = ("simulate", "analyze", "plot")
DEFAULT_SCALE = "quick"
DEV_ENV = "HHSCATTER_DEV_FALLBACK"


def dev_fallback_enabled() -> bool:
    """dev_fallback_enabled() -> True if ``HHSCATTER_DEV_FALLBACK=1`` is set (development only: a study may then
    use the paper's value for a missing upstream number, :mod:`hhscatter.studies._upstream`)."""
    return os.environ.get(DEV_ENV, "") == "1"


def studies_root() -> Path:
    """The studies folder commands work on: ``$HHSCATTER_STUDIES`` when set, else ``studies/`` of the repository the
    command runs in (the working directory or its nearest parent holding one); StudyError when there is none."""
    try:
        return _graph_default_root()
    except GraphError as exc:
        raise StudyError(str(exc)) from None


def study_names(root: Path | None = None) -> list[str]:
    """The names of the study folders (with a study.toml), each after the studies it needs."""

    try:
        return [s.name for s in studies(root if root is not None else studies_root())]
    except GraphError as exc:
        raise StudyError(str(exc)) from None


class ParamsView:
    """A study's typed ``Params`` (attribute access), recording each key read while ``study.params_read`` is a set.

    Without a ``Params`` model (a study folder without code) the keys are the raw ``[study]`` table's.
    """

    __slots__ = ("_study", "_model", "_raw")

    def __init__(self, study, model, raw: dict):
        self._study, self._model, self._raw = study, model, raw

    def __getattr__(self, key: str):
        study, model = self._study, self._model
        if model is not None:  # one key converted per read (typed_value), not the whole table
            if key not in model.model_fields:
                raise StudyError(f"study {study.name} reads [study] {key!r}, which its Params does not declare")
            value = typed_value(model, key, self._raw)
        elif key in self._raw:
            value = self._raw[key]
        else:
            raise StudyError(f"{study.root / 'study.toml'}: [study] needs '{key}'")
        if study.params_read is not None:
            study.params_read.add(key)
        return value

    def __repr__(self) -> str:
        if self._model is None:
            return f"ParamsView({self._raw!r})"
        return f"ParamsView({typed_params(self._model, self._raw)!r})"


@dataclass
class Study:
    """A study at one scale: its merged configuration and its output paths.

    ``config`` is ``study.toml`` with the scale's overrides applied; ``out`` is
    ``studies/<name>/out/<scale>/``.
    """

    name: str
    scale: str
    config: dict
    root: Path
    comparisons: list = field(default_factory=list)
    info: StudyInfo | None = None
    orbits_run: int = 0  # orbits integrated by this process's run() calls (the cost record)
    chunks_resumed: int = 0  # chunks found complete and kept by run()
    params_model: type | None = None  # the study's Params (hhscatter.studies.params.StudyParams) of its [study] table
    raw_runs: dict = field(default_factory=dict)  # key -> {scene_hash, orbits, complete}: the runs made/read
    params_read: set | None = None  # [study] keys read while this is a set (the simulate stage records them)

    @property
    def needs(self) -> dict:
        """The ``[needs]`` table: role -> name of the upstream study whose published outputs this study reads."""
        return dict(self.info.needs) if self.info else {}

    def upstream(self, role: str) -> str:
        """upstream(role) -> the study declared for ``role`` in ``[needs]``; a missing role is an error."""
        if role not in self.needs:
            raise StudyError(
                f"{self.root / 'study.toml'}: [needs] must name the study for {role!r} (has {sorted(self.needs)})"
            )
        return self.needs[role]

    @property
    def out(self) -> Path:
        """``<studies>/<name>/out/<scale>``: a study writes into its own folder."""
        return self.root / "out" / self.scale

    @property
    def raw_params(self) -> dict:
        """The ``[study]`` table as written in study.toml (after scale overrides)."""
        return self.config.get("study", {})

    @property
    def params(self) -> ParamsView:
        """The study's typed parameters: ``study.params.<key>`` is ``[study].<key>`` (or the default its ``Params``
        declares) converted to the declared type (Number → float, Integer → int, Numbers → list of floats, …;
        :func:`hhscatter.scene.schema.typed_params`). A key ``Params`` does not declare is a :class:`StudyError`;
        keys read while the simulate stage runs are recorded (``raw/done.json``)."""
        return ParamsView(
            self, self.params_model, self.raw_params
        )  # each read converts the current value (lists: copies)

    def param(self, key, default=None):
        """param(key) -> value of ``[study].key`` as written in study.toml, else the default its ``Params`` declares.

        The raw value (a TOML 1 is an int); study code reads :attr:`params` instead, typed.

        A key the study's ``Params`` does not declare is an error (the study
        file was checked against it when loaded, so this catches code that
        reads a key under another name). Without ``Params``, ``default`` is
        used and a missing key without default is an error.
        """
        if self.params_read is not None:
            self.params_read.add(key)
        p = self.raw_params
        if key in p:
            return p[key]
        if self.params_model is not None:
            f = self.params_model.model_fields.get(key)
            if f is None:
                raise StudyError(f"study {self.name} reads [study] {key!r}, which its Params does not declare")
            if not f.is_required():
                return copy.deepcopy(f.default)
        elif default is not None:
            return default
        raise StudyError(f"{self.root / 'study.toml'}: [study] needs '{key}'")

    @property
    def model(self) -> System:
        """The system of the study's ``[system]`` table, or Hénon–Heiles(ω, λ) of its ``[scene]``: E_c, exits, V."""
        if self.config.get("system") is not None:
            return system_from_spec(self.config["system"])
        sc = self.config.get("scene", {})
        return HenonHeiles(sc.get("omega", 1.0), sc.get("lam", 1.0))

    def scene(self, key: str, **overrides) -> Scene:
        """scene(key, **overrides) -> Scene from ``[scene]`` (+ ``[sections]``, ``[snapshots]``, ``[noise]``) and overrides.

        A relative ``ics`` path of study.toml is relative to the study's folder."""
        d = dict(self.config.get("scene", {}))
        for extra in ("sections", "snapshots", "noise", "system"):
            if extra in self.config:
                d[extra] = copy.deepcopy(self.config[extra])
        if isinstance(d.get("ics"), str) and d["ics"].strip() and not os.path.isabs(d["ics"]):
            d["ics"] = os.path.abspath(self.root / d["ics"])  # study.toml's paths are relative to its folder
        d.update(overrides)
        d = {k: v for k, v in d.items() if v is not None or k in ("sections", "snapshots")}
        d["name"] = f"{self.name}/{key}"
        return scene_from_dict(d)

    def raw(self, key: str) -> Path:
        return self.out / "raw" / key

    def derived(self, fname: str) -> Path:
        p = self.out / "derived" / fname
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    @property
    def numbers_path(self) -> Path:
        return self.out / f"{self.name}.json"

    @property
    def figure_path(self) -> Path:
        return self.out / f"{self.name}.png"

    def run(self, key: str, scene: Scene, *, workers=None, progress=True) -> Path:
        """run(key, scene, workers=None) -> raw run directory, integrating only what is missing.

        A finished run of the same scene is kept (chunks verified), an
        interrupted one resumed; a run of a different scene (the study file
        changed) is replaced. A key this study has already run with another scene is a
        :class:`~hhscatter.errors.StudyError` before any work (two runs would share one folder:
        make keys with :func:`hhscatter.studies.keys.number_key`).
        """

        made = self.raw_runs.get(key)
        if made is not None and made.get("scene_hash") != scene.result_hash():
            raise StudyError(
                f"study {self.name}: run key {key!r} was already used for another scene in this stage; two runs "
                "cannot share a key (a key formatted from a number can collide: make it with "
                "hhscatter.studies.keys.number_key)"
            )
        out = self.raw(key)
        resume, overwrite = False, False
        sj = out / SCENE_FILE
        if sj.exists():
            old = json.loads(sj.read_text()).get("scene_hash")
            resume = old == scene.result_hash()
            overwrite = not resume
        summary = simulate(scene, out, workers=workers, overwrite=overwrite, resume=resume, progress=progress)
        self.raw_runs[key] = {"scene_hash": scene.result_hash(), "orbits": int(scene.n), "complete": True}
        self.orbits_run += summary.n
        self.chunks_resumed += summary.chunks_skipped
        if summary.chunks_done:
            print(f"  {self.name}/{key}: {summary.line()}", flush=True)
        return out

    def compare(
        self,
        quantity: str,
        ours,
        err=None,
        paper=None,
        *,
        unit: str = "",
        note: str = "",
        verdict: str | None = None,
        convention: str | None = None,
        authors: bool = False,
        reference: str | None = None,
        paper_err: float | None = None,
        why: str = "",
        n: int | None = None,
    ) -> dict:
        """compare(quantity, ours, err=None, paper=None, *, convention=None, authors=False, ...) -> row dict.

        One row of the paper-vs-ours table. ``verdict`` defaults to an |Δ| ≤ 2σ test; the tables and pages
        judge the row by the one rule (:func:`~hhscatter.reproduction.verdicts.row_verdict`). ``reference``
        names the kind of ``paper`` (:data:`~hhscatter.reproduction.verdicts.REFERENCE_KINDS`: "printed" by
        the paper, "propagated" from printed numbers with its 1σ ``paper_err``, "exact" theory, "other": not the
        same quantity, with ``why``); without it the rule infers it
        (:func:`~hhscatter.reproduction.verdicts.reference_kind`). ``convention`` says how
        *our* number was made (default: the study's setup, :attr:`convention_label`); ``authors=True`` marks a
        row computed in the authors' own convention (their IC region, window or selection rule), so that a
        "differs" can be checked against it. The paper's number is always in the authors' convention. At a smoke
        scale (tiny) the row states no verdict (:data:`~hhscatter.reproduction.verdicts.NO_VERDICT`). ``n``: the
        number of trials when ``ours`` is a fraction of them; a fraction counted at 0 (or at all) is then judged and
        shown by its one-sided 95 % bound (:func:`~hhscatter.reproduction.verdicts.row_bound`), not by a σ.
        """
        if n is not None and (not isinstance(n, int) or isinstance(n, bool) or n <= 0):
            raise StudyError(f"compare({quantity!r}): n must be a positive number of trials, got {n!r}")
        if self.scale in SMOKE_SCALES:
            verdict = NO_VERDICT
        elif verdict is None and paper is not None and ours is not None and err is not None:
            try:
                verdict = "agrees within 2σ" if abs(float(ours) - float(paper)) <= 2 * float(err) else "differs"
            except (TypeError, ValueError):
                verdict = None
        conv = convention if convention is not None else self.convention_label
        if authors and not conv.startswith("authors"):
            conv = f"authors': {conv}"
        if reference is not None and reference not in REFERENCE_KINDS:
            raise StudyError(f"compare({quantity!r}): reference must be one of {', '.join(REFERENCE_KINDS)}")
        if reference == "propagated" and paper_err is None:
            raise StudyError(f"compare({quantity!r}): a propagated reference needs its 1σ paper_err")
        row = {
            "quantity": quantity,
            "ours": ours,
            "err": err,
            "paper": paper,
            "unit": unit,
            "verdict": verdict,
            "note": note,
            "convention": conv,
            "authors": bool(authors),
        }
        if reference is not None:
            row["reference_kind"] = reference
        if paper_err is not None:
            row["paper_err"] = float(paper_err)
        if why:
            row["why"] = why
        if n is not None:
            row["n"] = n
        if (reference is not None or row_bound(row) is not None) and self.scale not in SMOKE_SCALES:
            row["verdict"] = row_verdict(row, self.scale)
        self.comparisons.append(row)
        return row

    @property
    def convention_label(self) -> str:
        """The study's own setup in a few words: its ICs and the escape radius of its ``[scene]``. The ICs are
        ``[about] setup`` when the study says it (ICs that are not the ``[scene]``'s region, e.g. a grid on the
        section), else the ``[scene]``'s region."""
        sc = self.config.get("scene", {})
        region = sc.get("region", "disk")
        where = f"disk r < {sc.get('radius', 0.5):g}" if region == "disk" else f"{region} ICs"
        if self.info is not None and self.info.setup:
            where = self.info.setup
        r_esc = sc.get("r_esc")
        name = self.config.get("convention")
        head = f"{name} setup: " if name else ""
        return f"{head}{where}, r_esc {r_esc:g}" if r_esc is not None else f"{head}{where}"

    def write_numbers(self, numbers: dict) -> Path:
        """Write the study's numbers JSON (with its comparisons, scale and provenance).

        At a smoke scale (tiny) it states no verdict anywhere: every ``"verdict"`` reads
        :data:`~hhscatter.reproduction.verdicts.NO_VERDICT` (values and errors stay). It records what it was made from (:mod:`hhscatter.studies.provenance`: the hash of this study's
        configuration, of each upstream numbers JSON and the raw runs' scene hashes) and its own content hash.
        """

        ups = {name: doc for name, (_, doc) in self.upstream_numbers().items() if doc is not None}
        doc = {
            "study": self.name,
            "scale": self.scale,
            **without_verdicts(numbers, self.scale),
            "paper_comparison": without_verdicts(list(self.comparisons), self.scale),
            "config": self.config,
            "raw_runs": dict(self.raw_runs),
            # warnings of numpy/scipy in the analysis, counted instead of shown (hhscatter.analysis.stats.counted)
            "library_warnings": warning_counts(),
            "provenance": provenance(),
            "made_from": made_from(self, ups),
        }
        write_json_atomic(self.numbers_path, sealed(_jsonable(doc)))
        return self.numbers_path

    def read_numbers(self, other: str | None = None) -> dict:
        """read_numbers(other=None) -> numbers JSON of this study or of study ``other`` at the same scale, verified
        (:meth:`verify_numbers`: not edited, not stale)."""
        study = self if other is None else load_study(other, self.scale, root=self.root.parent)
        path = study.numbers_path
        if not path.exists():
            raise FileNotFoundError(f"{path} is missing: run `make {other or self.name} SCALE={self.scale}` first")
        doc = json.loads(path.read_text())
        study.verify_numbers(path, doc, upstream=not dev_fallback_enabled())
        return doc

    def upstream_numbers(self, pick=None) -> dict:
        """upstream_numbers(pick=None) -> {name: (path, numbers JSON or None)} of every study this one needs.

        ``pick(name) -> path`` chooses the file of an upstream study (default: its numbers JSON at this scale).
        """
        out = {}
        for other in sorted(set(self.needs.values())):
            path = (
                pick(other) if pick is not None else load_study(other, self.scale, root=self.root.parent).numbers_path
            )
            out[other] = (path, json.loads(path.read_text()) if path is not None and path.exists() else None)
        return out

    def verify_numbers(
        self, path: Path | None = None, doc: dict | None = None, *, pick=None, upstream: bool = True, raw: bool = True
    ) -> None:
        """verify_numbers(path=None, doc=None, *, pick=None, upstream=True, raw=True) -> None, or ProvenanceError.

        The study's numbers JSON (default: its own ``<name>.json``) checked against what it records
        (:func:`hhscatter.studies.provenance.verify_numbers`): its content, this study's configuration now,
        the upstream numbers JSON (``pick`` as for :meth:`upstream_numbers`; ``upstream=False`` skips them)
        and, with ``raw``, its raw runs when they are here (``out/raw/done.json``). ProvenanceError: exit 2.
        """
        path = Path(path) if path is not None else self.numbers_path
        doc = json.loads(path.read_text()) if doc is None else doc
        ups = self.upstream_numbers(pick) if upstream else {}
        verify_numbers(
            path,
            doc,
            config=_jsonable(self.config),
            scale=self.scale,
            upstream=ups,
            raw=self.out / "raw" if raw else None,
            remake=f"make it again with `make {self.name} SCALE={self.scale}`",
        )

    def write_table(self, df, fname: str, **meta) -> Path:
        """Write a derived pandas table as Parquet with the study config and provenance in its metadata."""
        import pyarrow as pa  # deferred: pyarrow loads on first use

        table = pa.Table.from_pandas(df, preserve_index=False)
        doc = {"study": self.name, "scale": self.scale, "config": self.config, **meta, "versions": provenance()}
        path = self.derived(fname)
        write_part(path, table, _jsonable(doc))
        return path

    def write_table_streamed(self, tables, fname: str, **meta) -> Path:
        """write_table_streamed(iterable of Arrow tables, fname, **meta) -> path: a derived table too large to hold
        at once (e.g. one part per γ of 1e7 rows), written part by part with the study's metadata."""

        doc = {"study": self.name, "scale": self.scale, "config": self.config, **meta, "versions": provenance()}
        path = self.derived(fname)
        write_parts_streamed(path, tables, _jsonable(doc))
        return path


def load_study(name: str, scale: str = DEFAULT_SCALE, root: Path | None = None) -> Study:
    """The study ``<root>/<name>/study.toml`` at a scale, its file checked strictly before any work."""
    root = Path(root) if root is not None else studies_root()
    path = root / name / "study.toml"
    if not path.exists():
        known = sorted(p.parent.name for p in root.glob("*/study.toml"))
        raise StudyError(f"study must be one of {known}, got {name!r}{did_you_mean(name, known)}")
    try:
        doc = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path} is not valid TOML: {exc}") from None
    params = _params_model(name, root)

    validate_study_file(doc, _shown(path), params)  # every table, key and type, at every scale, before any work
    if "convention" in doc:  # the shared scene keys (studies/conventions.toml) under the study's own [scene]
        cpath = conventions_path(root)
        doc = apply_convention(doc, load_conventions(cpath), _shown(path), _shown(cpath))
    try:
        info = study_info(root, name, doc)
    except GraphError as exc:
        raise StudyError(str(exc)) from None
    for key in HEADER_TABLES:  # what the study is and needs; not parameters of its runs
        doc.pop(key, None)
    scales = doc.pop("scale", {})
    if scale != DEFAULT_SCALE:
        if scale not in scales:
            raise StudyError(f"scale must be one of {[DEFAULT_SCALE, *scales]}, got {scale!r}")
        doc = merge_tables(doc, scales[scale])
    return Study(name=name, scale=scale, config=doc, root=root / name, info=info, params_model=params)


CONVENTIONS_FILE = "conventions.toml"


def conventions_path(root: Path | None = None) -> Path:
    """The shared scene conventions of a studies folder: ``<root>/conventions.toml``."""
    return (Path(root) if root is not None else studies_root()) / CONVENTIONS_FILE


def load_conventions(path: Path | None = None) -> dict:
    """The conventions file as {name: {scene key: value}}, strictly checked."""

    path = Path(path) if path is not None else conventions_path()
    try:
        doc = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise StudyError(f"{_shown(path)} is missing (the shared conventions of the studies)") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{_shown(path)} is not valid TOML: {exc}") from None
    validate_conventions_file(doc, _shown(path))
    return doc


def _shown(path: Path) -> str:
    """A path as the user would type it: relative to the working directory when it lies below it."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def _params_model(name: str, root: Path):
    """The ``Params`` model of the study's module (None: a study folder without code, or without Params)."""
    if not (Path(root) / name / "study.py").is_file():
        return None
    return getattr(stage_module(name, root), "Params", None)


def missing_upstream(study: Study) -> list[str]:
    """The declared upstream studies whose numbers JSON (same scale) is not there yet."""
    out = []
    for other in sorted(set(study.needs.values())):
        try:
            path = load_study(other, study.scale, root=study.root.parent).numbers_path
        except StudyError:
            out.append(other)
            continue
        if not path.exists():
            out.append(other)
    return out


#: the study.toml tables every raw run's scene is made from (Study.scene, Study.model)
SCENE_TABLES = ("scene", "sections", "snapshots", "follow", "noise", "system")


def simulate_inputs(study, keys) -> dict:
    """simulate_inputs(study, keys) -> what the simulate stage made its runs from: the scene tables of
    study.toml (this scale) and the values of the ``[study]`` keys it read (``keys``). Analysis-only keys
    (a paper constant, a fit window) are not in it: changing them needs no new simulation."""
    return _jsonable(
        {"tables": {t: study.config.get(t) for t in SCENE_TABLES}, "study": {k: study.param(k) for k in sorted(keys)}}
    )


# -- a study's code is loaded from its folder by path: studies/<name>/study.py becomes the module
# hhscatter_study_<name>.study of a package whose path is that folder (so `from .figure import …` works); a folder
# of the same name in another studies root gets a package of its own
_LOADED: dict[Path, object] = {}  # study folder (resolved) -> its study module


def stage_module(name: str, root: Path | None = None):
    """The module ``<root>/<name>/study.py`` (default root: :func:`studies_root`), loaded from that file.

    The study folder is a package of its own (``hhscatter_study_<name>``), so its modules import each other
    relatively (``from .figure import …``) and the library absolutely. Loaded once per folder.
    """
    folder = ((Path(root) if root is not None else studies_root()) / name).resolve()
    if folder in _LOADED:
        return _LOADED[folder]
    path = folder / "study.py"
    if not path.is_file():
        raise StudyError(f"{_shown(path)} is missing: a study folder holds its study.toml and study.py")
    pkg_name = f"hhscatter_study_{''.join(c if c.isalnum() else '_' for c in name)}"
    if pkg_name in sys.modules:  # a study of that name from another folder is loaded already
        pkg_name = f"{pkg_name}_{len(_LOADED)}"
    pkg = types.ModuleType(pkg_name, f"the study folder {folder}")
    pkg.__path__ = [str(folder)]
    sys.modules[pkg_name] = pkg
    spec = importlib.util.spec_from_file_location(f"{pkg_name}.study", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # (dataclasses look their module up while the file executes)
    try:
        spec.loader.exec_module(mod)
    except BaseException:
        del sys.modules[spec.name], sys.modules[pkg_name]
        raise
    _LOADED[folder] = mod
    return mod
