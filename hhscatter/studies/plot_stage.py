"""The ``plot`` stage of a study, declared: which figure function draws which derived tables.

Every study's ``plot`` stage does the same thing: it reads derived tables of its ``out/<scale>/derived/``
folder, the verified numbers JSON and a few ``[study]`` parameters, and hands them to a function of the study's
``figure.py`` with the figure's path. :func:`figure_stage` makes that stage from a declaration, so a study states
only its figure function and what each argument is::

    plot = figure_stage(
        "plot_fig4", "fig4_survival", "fig4_ratio", "fig4_tau", NUMBERS, PATH, mark_gamma=Param("mark_gamma")
    )

An argument is a derived table's file name (``"fig4_survival"`` reads ``derived/fig4_survival.parquet``;
:class:`Table` with ``optional=True`` gives ``None`` when the table is absent), :data:`NUMBERS` (the study's numbers
JSON, verified by :meth:`~hhscatter.studies.study.Study.read_numbers`), :data:`PATH` (the study's figure path,
``out/<scale>/<name>.png``), :data:`SCALE` (the scale's name), or :class:`Param` (a ``[study]`` parameter).
The stage computes nothing: it draws from the published outputs only.
"""

from __future__ import annotations

import importlib
from typing import NamedTuple

from hhscatter.errors import StudyError
from hhscatter.studies import _upstream as up
from hhscatter.studies.study import stage_module


class Table(NamedTuple):
    """A derived table ``derived/<name>.parquet`` as a DataFrame.

    When the file is absent: an error (default), ``None`` with ``optional=True``, or the figure is not drawn
    with ``skip=True``.

    Examples
    --------
    >>> Table("fig4_ratio").file, Table("kappa_conventions", optional=True).optional
    ('fig4_ratio.parquet', True)
    """

    name: str
    optional: bool = False
    skip: bool = False

    @property
    def file(self) -> str:
        """The table's file name in ``derived/``."""
        return self.name if self.name.endswith(".parquet") else f"{self.name}.parquet"


class Param(NamedTuple):
    """The ``[study]`` parameter ``name`` of the study (``study.params.<name>``).

    Examples
    --------
    >>> Param("mark_gamma").name
    'mark_gamma'
    """

    name: str


class Upstream(NamedTuple):
    """The table that the upstream study of ``[needs] <role>`` publishes under ``key``; ``None`` if it has none.

    Examples
    --------
    >>> Upstream("cmeasure", "cmeasure_points").key
    'cmeasure_points'
    """

    role: str
    key: str


class Sibling(NamedTuple):
    """The path of a second figure beside the study's: ``out/<scale>/<name><suffix>.png``.

    Examples
    --------
    >>> Sibling("_residuals").suffix
    '_residuals'
    """

    suffix: str


class _Skip(Exception):
    """A table declared ``skip=True`` is absent: the figure is not drawn."""


class _Input(NamedTuple):
    what: str


NUMBERS = _Input("numbers")  # the study's numbers JSON, verified
PATH = _Input("path")  # the study's figure path out/<scale>/<name>.png
SCALE = _Input("scale")  # the scale's name


def _value(study, spec):
    if isinstance(spec, str):
        spec = Table(spec)
    if isinstance(spec, Table):
        import pandas as pd  # deferred: pandas loads with the stage that reads tables, not with the study module

        path = study.out / "derived" / spec.file
        if (spec.optional or spec.skip) and not path.exists():
            if spec.skip:
                raise _Skip(spec.name)
            return None
        return pd.read_parquet(path)
    if isinstance(spec, Upstream):
        try:
            return up.published_table(study, study.upstream(spec.role), spec.key)[0]
        except up.UpstreamError:
            return None
    if isinstance(spec, Sibling):
        return study.figure_path.with_name(f"{study.name}{spec.suffix}.png")
    if isinstance(spec, Param):
        return getattr(study.params, spec.name)
    if spec is NUMBERS:
        return study.read_numbers()
    if spec is PATH:
        return study.figure_path
    if spec is SCALE:
        return study.scale
    raise StudyError(
        f"figure_stage: an argument is a table name, Table, Param, Upstream, Sibling, NUMBERS, PATH or SCALE, got {spec!r}"
    )


def figure_function(study, name: str):
    """figure_function(study, name) -> the function ``name`` of the study's ``figure.py`` (imported on first use).

    The figure module is the sibling of the study's ``study.py`` in its folder's package
    (:func:`~hhscatter.studies.study.stage_module`), so the plotting library loads with the ``plot`` stage only.

    Examples
    --------
    >>> from hhscatter.studies import load_study
    >>> figure_function(load_study("fig4", "tiny"), "plot_fig4").__name__
    'plot_fig4'
    """
    package = stage_module(study.name, study.root.parent).__package__
    return getattr(importlib.import_module(f"{package}.figure"), name)


def figure_stage(draw: str, *args, when=None, **kwargs):
    """figure_stage(draw, *args, **kwargs) -> the study's ``plot(study)`` stage: ``figure.<draw>(*args, **kwargs)``.

    Each argument is declared (see the module's introduction): a derived table's name or :class:`Table`,
    :class:`Param`, :data:`NUMBERS`, :data:`PATH` or :data:`SCALE`; the stage reads them in the order given and
    calls the study's figure function ``draw`` with them. Nothing is read before the stage runs. ``when``: a
    ``[study]`` parameter's name and a value it must hold (``("parts", "claims")``: drawn only when
    ``"claims"`` is in ``[study] parts``); a table declared ``Table(name, skip=True)`` that is absent skips the
    figure too. Several stages are one with :func:`figures`.

    Examples
    --------
    >>> plot = figure_stage("plot_fig4", "fig4_survival", NUMBERS, PATH, mark_gamma=Param("mark_gamma"))
    >>> plot.__doc__
    'plot(study) -> None: figure.plot_fig4(fig4_survival, numbers, path, mark_gamma=[study] mark_gamma).'
    """
    for spec in (*args, *kwargs.values()):
        if not isinstance(spec, (str, Table, Param, Upstream, Sibling, _Input)):
            raise StudyError(
                f"figure_stage({draw!r}): an argument is a table name, Table, Param, Upstream, Sibling, NUMBERS, PATH or SCALE, "
                f"got {spec!r}"
            )

    def plot(study):
        if when is not None and when[1] not in getattr(study.params, when[0]):
            return
        try:
            values = [_value(study, spec) for spec in args]
            named = {key: _value(study, spec) for key, spec in kwargs.items()}
        except _Skip:
            return
        figure_function(study, draw)(*values, **named)

    def shown(spec):
        if isinstance(spec, str):
            spec = Table(spec)
        if isinstance(spec, Table):
            return spec.file.removesuffix(".parquet") + ("?" if spec.optional or spec.skip else "")
        if isinstance(spec, Param):
            return f"[study] {spec.name}"
        if isinstance(spec, Upstream):
            return f"{spec.role}:{spec.key}?"
        if isinstance(spec, Sibling):
            return f"<name>{spec.suffix}.png"
        return spec.what

    listed = [shown(s) for s in args] + [f"{k}={shown(s)}" for k, s in kwargs.items()]
    cond = "" if when is None else f" if {when[1]!r} in [study] {when[0]}"
    plot.__doc__ = f"plot(study) -> None: figure.{draw}({', '.join(listed)}){cond}."
    return plot


def figures(*stages):
    """figures(*stages) -> one ``plot(study)`` stage drawing the figures of the :func:`figure_stage` s in order.

    Examples
    --------
    >>> plot = figures(figure_stage("plot_a", NUMBERS, PATH), figure_stage("plot_b", NUMBERS, Sibling("_b")))
    >>> print(plot.__doc__)
    plot(study) -> None: the figures in order:
    plot(study) -> None: figure.plot_a(numbers, path).
    plot(study) -> None: figure.plot_b(numbers, <name>_b.png).
    """

    def plot(study):
        for stage in stages:
            stage(study)

    plot.__doc__ = "plot(study) -> None: the figures in order:\n" + "\n".join(s.__doc__ for s in stages)
    return plot
