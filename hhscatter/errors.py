"""The errors hhscatter raises on purpose: one family, each with the exit status of the ``hhscatter`` command.

Every error a user can cause (a bad scene, an unusable output directory, a broken run, a study that cannot run)
is an :class:`HHScatterError`; the CLI prints its message, without a traceback, and exits with
:attr:`HHScatterError.exit_code` (2 for bad input, before any work and before anything is written; 1 for a run
that could not complete). Anything else is a bug and keeps its traceback.

| error | exit status | raised when |
|---|---|---|
| :class:`ConfigError` (alias :data:`SceneError`; also a ValueError) | 2 | a scene, grid, study or conventions file or parameter is invalid |
| :class:`SetupError` | 2 | an optional package a request needs is not installed |
| :class:`OutputError` | 2 | the output location cannot take the run (not empty, another scene, locked by another writer, not writable) |
| :class:`RunIntegrityError` | 2 | a run directory's tables differ from its manifest (missing, damaged, extra or foreign parts) |
| :class:`IncompleteRunError` | 2 | a run directory's chunks are not all finished |
| :class:`StudyError` | 2 | a study cannot run a stage (unknown study or stage, missing or stale inputs, an unreadable study graph) |
| :class:`RunError` | 1 | a run could not complete (finished chunks are kept) |

Examples
--------
>>> import hhscatter
>>> from hhscatter.errors import ConfigError, HHScatterError
>>> try:
...     hhscatter.Scene(energy=0.3, n=0)
... except HHScatterError as e:
...     print(type(e).__name__, e.exit_code, e)
ConfigError 2 n (number of orbits) must be an integer > 0, got 0
>>> hhscatter.SceneError is ConfigError
True
"""

from __future__ import annotations

__all__ = [
    "ConfigError",
    "HHScatterError",
    "IncompleteRunError",
    "OutputError",
    "RunError",
    "RunIntegrityError",
    "SceneError",
    "SetupError",
    "StudyError",
]


class HHScatterError(Exception):
    """The base of every error hhscatter raises on purpose; ``exit_code`` is the CLI's exit status for it.

    Examples
    --------
    >>> import hhscatter
    >>> try:
    ...     hhscatter.read_lifetimes("/no/such/run")
    ... except hhscatter.HHScatterError as e:
    ...     print(type(e).__name__, e.exit_code)
    ... except FileNotFoundError as e:
    ...     print("FileNotFoundError")
    FileNotFoundError
    >>> issubclass(hhscatter.ConfigError, hhscatter.HHScatterError), hhscatter.RunError.exit_code
    (True, 1)
    """

    exit_code = 2


class ConfigError(HHScatterError, ValueError):
    """A scene, grid, study or conventions file or parameter is invalid (unknown key, wrong type, out of range).

    Raised before any work and before anything is written; the CLI prints its message and exits with 2.

    Examples
    --------
    >>> import hhscatter
    >>> try:
    ...     hhscatter.Scene(energy=0.3, n=0)
    ... except hhscatter.SceneError as e:
    ...     print(e)
    n (number of orbits) must be an integer > 0, got 0
    """


#: The name of :class:`ConfigError` before the error family existed (kept so that user code does not break).
SceneError = ConfigError


class SetupError(HHScatterError, ImportError):
    """An optional package a request needs is not installed (the message names the extra to install)."""


class OutputError(HHScatterError):
    """The output location cannot take the run: not empty, holding another scene, locked, or not writable."""


class RunIntegrityError(HHScatterError, ValueError):
    """A run directory is not what its manifest (``scene.json``) plans: a table or part is missing, damaged,
    not in the chunk plan, or made by another scene.

    Examples
    --------
    >>> import pathlib, shutil, tempfile, hhscatter
    >>> run = pathlib.Path(tempfile.mkdtemp())
    >>> _ = hhscatter.simulate(hhscatter.Scene(energy=0.3, n=20, t_max=5.0), run, overwrite=True,
    ...                        workers=1, progress=False)
    >>> shutil.rmtree(run / "lifetimes")
    >>> try:
    ...     hhscatter.read_lifetimes(run)
    ... except hhscatter.RunIntegrityError as e:
    ...     print(type(e).__name__, "missing" in str(e), e.exit_code)
    RunIntegrityError True 2
    """


class IncompleteRunError(RunIntegrityError):
    """A run directory's chunks are not all finished (read with ``allow_partial=True`` to use the finished ones)."""


class StudyError(HHScatterError, ValueError):
    """A study cannot run a stage: unknown study or stage, missing or stale inputs, an unreadable study graph.

    Examples
    --------
    >>> import hhscatter
    >>> from hhscatter.studies import run_stage
    >>> try:
    ...     run_stage("fig9", "simulate", "quick")
    ... except hhscatter.StudyError as e:
    ...     print(type(e).__name__, e.exit_code)
    StudyError 2
    """


class RunError(HHScatterError, RuntimeError):
    """A run could not complete (e.g. a part file could not be written); finished chunks are kept.

    The CLI exits with 1 (not 2: the input was fine); ``--resume`` continues the run.

    Examples
    --------
    >>> import hhscatter
    >>> hhscatter.RunError("disk full").exit_code
    1
    """

    exit_code = 1
