"""The base of a study's ``Params``: the keys of its ``[study]`` table, declared with the leaf types of
:mod:`hhscatter.scene.schema` (``Number``, ``Integer``, ``Numbers``, …)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict

__all__ = ["StudyParams"]


class StudyParams(BaseModel):
    """Base of a study's ``Params``: the keys of its ``[study]`` table, strictly typed; no other key is allowed.

    A study declares ``class Params(StudyParams)`` with one field per key (leaf types
    :data:`~hhscatter.scene.schema.Number`, :data:`~hhscatter.scene.schema.Integer`,
    :data:`~hhscatter.scene.schema.Numbers`, …, a default where the key is optional); study.toml is checked
    against it when the study is loaded, and the study's code reads ``study.params.<key>``, converted by
    :func:`~hhscatter.scene.schema.typed_params` (Number → float, Integer → int, Numbers → list of floats, …).

    Examples
    --------
    >>> from hhscatter.scene.schema import Integer, Numbers, typed_params
    >>> class Params(StudyParams):
    ...     energies: Numbers
    ...     n: Integer = 10
    >>> typed_params(Params, {"energies": [0.3, 1]}).n
    10
    """

    model_config = ConfigDict(extra="forbid")
