"""Grid runs: one job over every (E0, γ) of a sweep, written as one dataset per table.

A scene whose ``energy`` and/or ``gamma`` is a list is a grid, e.g. in TOML::

    [scene]
    energy = [0.25, 0.3]
    gamma = [0, 0.01]
    n = 100000

or on the command line ``hhscatter simulate --energy 0.25,0.3 --gamma 0,0.01 …``.
Its points are the Cartesian product (energy-major order), each an ordinary
:class:`~hhscatter.scene.scene.Scene` that differs from the others only in
``energy`` and ``gamma``. The runner schedules the tasks (energy, γ, chunk)
of all points as one job and writes each point to its own folder::

    OUT/lifetimes/E0.25_gamma0.01/part-000000.parquet

each part carrying its own point's scene and hash in its metadata, and its
point as float64 columns (``energy`` and ``gamma`` in ``lifetimes``;
``point_energy`` and ``point_gamma`` in ``sections`` and ``snapshots``). The
folder names are deliberately not hive ``key=value`` pairs: a hive key is
typed as a string (or dictionary) by pyarrow, pandas and DuckDB, and clashes
with a file column of the same name, so the runs of hhscatter ≤ 0.1.0
(``energy=0.25/gamma=0.01/``) did not open in those readers. With the point in
the files, pandas, pyarrow, DuckDB and polars read the same numeric frame
(see :mod:`hhscatter.data.schema`). The column is ``energy``, not ``e0``: ``e0`` is
each orbit's computed initial energy, which differs from the nominal E0 in
the last bits, so group by ``energy``, never by ``e0``.

Seeds and pairing: every point uses the scene's ``seed``, so orbit i of every
point is drawn from the same random numbers (:mod:`hhscatter.scene.ics`). Across γ
the initial conditions are identical; across energies on the default disk
(R = 0.5 lies inside the E_c contour, so no candidate is rejected for
E0 > E_c) orbit i starts at the same position with the speed of its energy.
The sweep thus compares paired ensembles, which removes the ensemble-to-
ensemble noise from differences between points. Give points different seeds
by running them as separate scenes if independent ensembles are wanted.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass, field

from hhscatter.errors import ConfigError
from hhscatter.scene.scene import Scene, _clean, _json_default, scene_from_dict
from hhscatter.scene.schema import scene_dict_from_toml

AXES = ("energy", "gamma")


def _values(name, v) -> tuple:
    vals = tuple(v) if isinstance(v, (list, tuple)) else (v,)
    if not vals:
        raise ConfigError(f"{name} must be a number or a non-empty list of numbers")
    out = []
    for x in vals:
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise ConfigError(f"{name} must be a number or a list of numbers, got {x!r}")
        x = float(x) + 0.0  # −0.0 is 0.0 (the same point: one folder, one hash)
        if not math.isfinite(x):
            raise ConfigError(f"{name} must be finite, got {x}")
        out.append(x)
    if len(set(out)) != len(out):
        raise ConfigError(f"{name} lists a value twice: {out}")
    return tuple(out)


@dataclass(frozen=True)
class Grid:
    """A sweep of scenes over E0 and/or γ: the points base.replace(energy=E, gamma=γ), E-major.

    ``base`` carries every other scene field (n per point, seed, chunk_size…). Each point is validated as
    a scene when the grid is made. :func:`hhscatter.simulate` writes one run for the whole grid; its
    tables carry the point's nominal ``energy`` and ``gamma``.

    Parameters
    ----------
    base : Scene
        Every field but energy and γ.
    energies : tuple of float
        Initial energies E0 (units of the potential; E0 > E_c = ω⁶/(6λ²), Eq. (eqn:hh_potential)).
    gammas : tuple of float
        Drag coefficients γ ≥ 0 (1/time).

    Raises
    ------
    ConfigError
        A point is not a valid scene (e.g. E0 ≤ E_c), or the lists are empty.

    Examples
    --------
    >>> import hhscatter
    >>> grid = hhscatter.Grid(hhscatter.Scene(energy=0.3, n=1000), energies=(0.25, 0.3), gammas=(0.0, 0.01))
    >>> [(p.energy, p.gamma) for p in grid.points]
    [(0.25, 0.0), (0.25, 0.01), (0.3, 0.0), (0.3, 0.01)]
    """

    base: Scene
    energies: tuple
    gammas: tuple
    _points: tuple = field(default=(), init=False, repr=False, compare=False)

    def __post_init__(self):
        if self.base.ics is not None:
            raise ConfigError("a grid needs energy-based initial conditions: ics tables cannot be swept")
        es, gs = _values("energy", self.energies), _values("gamma", self.gammas)
        object.__setattr__(self, "energies", es)
        object.__setattr__(self, "gammas", gs)
        object.__setattr__(self, "_points", tuple(self.base.replace(energy=e, gamma=g) for e in es for g in gs))

    @property
    def points(self) -> tuple:
        """Scenes of the grid, energy-major."""
        return self._points

    @property
    def name(self) -> str:
        return self.base.name

    @property
    def n(self) -> int:
        """Total number of orbits over all points."""
        return self.base.n * len(self._points)

    @staticmethod
    def partition(scene: Scene) -> str:
        """partition(scene) -> folder of a point, 'E<E0>_gamma<γ>' (Python repr of the floats; no '=', see module doc)."""
        return f"E{float(scene.energy)!r}_gamma{float(scene.gamma)!r}"

    def to_dict(self) -> dict:
        d = self.base.to_dict()
        d["energy"], d["gamma"] = list(self.energies), list(self.gammas)
        return d

    def to_json(self) -> str:

        return json.dumps(_clean(self.to_dict()), sort_keys=True, allow_nan=False, default=_json_default)

    def result_hash(self) -> str:
        """sha256 over the points' result hashes (their order included)."""
        return hashlib.sha256(json.dumps([p.result_hash() for p in self._points]).encode()).hexdigest()


def is_grid_dict(d: dict) -> bool:
    return any(isinstance(d.get(k), (list, tuple)) for k in AXES)


def run_from_dict(d: dict):
    """run_from_dict(d) -> Scene, or Grid when ``energy`` or ``gamma`` is a list."""
    if not is_grid_dict(d):
        return scene_from_dict(d)
    d = dict(d)
    energies, gammas = _values("energy", d.get("energy")), _values("gamma", d.get("gamma", 0.0))
    d["energy"], d["gamma"] = energies[0], gammas[0]
    return Grid(scene_from_dict(d), energies, gammas)


def load_run(path: str | os.PathLike[str], scale: str | None = None, **overrides: object) -> Scene | Grid:
    """A Scene, or a Grid when ``energy`` or ``gamma`` is a list, from a scene TOML file.

    Parameters
    ----------
    path : path
        The TOML file: ``[scene]`` (Scene fields), optional ``[sections]``, ``[snapshots]`` and
        ``[scale.<name>]`` tables (see :func:`hhscatter.load_scene`).
    scale : str, optional
        A ``[scale.<name>]`` table whose keys override ``[scene]``.
    **overrides
        Scene fields applied last.

    Returns
    -------
    Scene or Grid

    Raises
    ------
    ConfigError
        An unknown table or key (with a did-you-mean), or a value out of range.

    Examples
    --------
    >>> import pathlib, tempfile, hhscatter
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "scene.toml"
    >>> _ = f.write_text("[scene]\\nenergy = [0.25, 0.3]\\nn = 1000\\n")
    >>> type(hhscatter.load_run(f)).__name__, len(hhscatter.load_run(f).points)
    ('Grid', 2)
    """
    return run_from_dict(scene_dict_from_toml(path, scale, **overrides))
