"""Exit basins: the basin map of a grid of initial conditions per grid point, its shares, entropies and Wada test."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from hhscatter.api import checks
from hhscatter.api.plotting import _axes
from hhscatter.api.points import _label, _sorted_keys, split_points
from hhscatter.errors import ConfigError

if TYPE_CHECKING:  # annotations only: pandas and matplotlib are imported when a function runs
    import pandas
    from matplotlib.axes import Axes
    from numpy.typing import ArrayLike


#: basin codes of :func:`basin_measures`: the exit channel number for an escape, these two otherwise
SETTLED_BASIN, TRAPPED_BASIN, OUTSIDE_BASIN = 100, 101, -1


def _basin_name(code: int) -> str:
    return {SETTLED_BASIN: "settled", TRAPPED_BASIN: "trapped"}.get(int(code), f"exit {int(code)}")


@dataclass(frozen=True)
class BasinMeasures:
    """Result of :func:`basin_measures`: exit-basin maps and their measures, per grid point.

    Attributes
    ----------
    maps : dict
        (energy, gamma) → int array (ny, nx): exit channel of each cell's orbit, ``SETTLED_BASIN`` (100),
        ``TRAPPED_BASIN`` (101, still inside at t_max), ``OUTSIDE_BASIN`` (−1, no orbit: energetically forbidden).
    fractions : dict
        (energy, gamma) → :class:`~hhscatter.analysis.geometry.basins.BasinFractions` (share of each basin, Wilson 1σ).
    entropy : dict
        (energy, gamma) → :func:`~hhscatter.analysis.geometry.basins.basin_entropy_table` (S_b, S_bb per box side).
    wada : dict
        (energy, gamma) → :class:`~hhscatter.analysis.geometry.basins.WadaTest`, or None (``wada=False``).
    extent : tuple or None
        (x0, x1, y0, y1) of the maps, for :meth:`plot`.
    """

    maps: dict
    fractions: dict
    entropy: dict
    wada: dict
    extent: tuple | None = None

    def to_frame(self) -> pandas.DataFrame:
        """The measures as a DataFrame, one row per (point, box side): energy, gamma, box, S_b, S_b_err, S_bb, S_bb_err,
        a column ``share <basin>`` per basin, wada (verdict, or None)."""
        import pandas as pd  # deferred: pandas loads on first use

        parts = []
        for k in _sorted_keys(self.maps):
            fr, w = self.fractions[k], self.wada.get(k)
            shares = {f"share {_basin_name(b)}": float(f) for b, f in zip(fr.basins, fr.frac)}
            parts.append(
                self.entropy[k][["box", "S_b", "S_b_err", "S_bb", "S_bb_err"]].assign(
                    energy=k[0], gamma=k[1], **shares, wada=None if w is None else bool(w.wada)
                )
            )
        df = pd.concat(parts, ignore_index=True)
        return df[["energy", "gamma", *[c for c in df.columns if c not in ("energy", "gamma")]]]

    def plot(self, ax: Axes | None = None, *, key: tuple[float, float] | None = None, **imshow_kwargs: Any) -> Axes:
        """Draw the basin map of point ``key`` (default: the first), one colour per basin, forbidden cells blank."""
        from matplotlib.colors import ListedColormap  # deferred: matplotlib loads on first use
        from matplotlib.patches import Patch  # deferred: matplotlib loads on first use

        ax = _axes(ax)
        k = key if key is not None else _sorted_keys(self.maps)[0]
        lab = self.maps[k]
        codes = sorted(int(c) for c in np.unique(lab) if c != OUTSIDE_BASIN)
        colours = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:brown", "tab:pink"]
        palette = {
            c: ("0.55" if c == TRAPPED_BASIN else "orange" if c == SETTLED_BASIN else colours[i % 6])
            for i, c in enumerate(codes)
        }
        index = np.full(lab.shape, np.nan)
        for i, c in enumerate(codes):
            index[lab == c] = i
        ax.imshow(
            index,
            origin="lower",
            extent=self.extent,
            interpolation="nearest",
            cmap=ListedColormap([palette[c] for c in codes]),
            vmin=-0.5,
            vmax=len(codes) - 0.5,
            **imshow_kwargs,
        )
        ax.legend(
            handles=[Patch(color=palette[c], label=_basin_name(c)) for c in codes], loc="upper right", fontsize="small"
        )
        ax.set_title(_label(k))
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        return ax


def basin_measures(
    lifetimes: pandas.DataFrame,
    cell: ArrayLike,
    shape: tuple[int, int],
    *,
    boxes: tuple[int, ...] = (2, 5, 10),
    extent: tuple[float, float, float, float] | None = None,
    wada: bool = True,
) -> BasinMeasures:
    """Exit-basin maps of a grid of initial conditions, per grid point, with their basin measures.

    Each cell of a (ny, nx) grid of initial conditions (e.g. :func:`hhscatter.scene.ics.section_grid`, which also gives
    ``cell``) is coloured by its orbit's fate: the exit channel it escaped through, settled (its energy fell
    below E_c inside Ω, with drag), or trapped (inside at t_max). Measures of each map: the share of every basin
    (:func:`~hhscatter.analysis.geometry.basins.basin_fractions`), the basin entropy S_b and boundary basin entropy S_bb
    at each box side (Daza et al. 2016; :func:`~hhscatter.analysis.geometry.basins.basin_entropy_table`) and the Wada
    test by merging (:func:`~hhscatter.analysis.geometry.basins.wada_merging`, on the basins holding ≥ 0.5 % of the
    cells). Beyond the paper (study basins).

    Parameters
    ----------
    lifetimes : DataFrame
        :func:`hhscatter.read_lifetimes` of runs of those initial conditions (``traj_id`` = row of the IC table;
        several γ concatenated are several points). Needs the columns traj_id, outcome, exit_channel.
    cell : int array (m,)
        Flat (row-major) index into the (ny, nx) grid of IC row i.
    shape : (int, int)
        (ny, nx).
    boxes : sequence of int
        Box sides (cells) of the basin entropy.
    extent : (x0, x1, y0, y1), optional
        The grid's extent, for the plot's axes.
    wada : bool
        Run the Wada test (the slowest part on large maps).

    Returns
    -------
    BasinMeasures
        ``.maps`` the label arrays, ``.to_frame()`` one row per (point, box side), ``.plot(ax=, key=)`` a map.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> lab = np.repeat([0, 1], 32)                                       # left half exit 0, right half exit 1
    >>> cell = np.arange(64 * 64)
    >>> lt = pd.DataFrame({"traj_id": cell, "gamma": 0.0, "e0": 0.3, "outcome": "escaped",
    ...                    "exit_channel": np.tile(lab, 64), "t_end": 1.0})
    >>> m = hhscatter.basin_measures(lt, cell, (64, 64), boxes=[4], wada=False)
    >>> m.maps[(0.3, 0.0)][0, :3].tolist(), m.to_frame()[["box", "share exit 0"]].values.tolist()
    ([0, 0, 0], [[4.0, 0.5]])
    """
    from hhscatter.analysis.geometry.basins import (  # deferred: pandas, pyarrow, scipy load on first use
        basin_entropy_table,
        basin_fractions,
        wada_merging,
    )

    checks.frame(lifetimes, "lifetimes", needs=("traj_id", "outcome", "exit_channel", "t_end"))
    try:
        cell = np.asarray(cell).ravel()
        ok = cell.size > 0 and np.issubdtype(cell.dtype, np.integer)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ConfigError(f"cell must be a non-empty array of integer cell indices, got {checks.describe(cell)}")
    cell = cell.astype(np.int64)
    if not (isinstance(shape, (tuple, list)) and len(shape) == 2):
        raise ConfigError(f"shape must be (ny, nx), got {checks.describe(shape)}")
    ny, nx = (checks.number(v, f"shape[{i}]", lo=1, integer=True) for i, v in enumerate(shape))
    if cell.min() < 0 or cell.max() >= ny * nx:
        raise ConfigError(
            f"cell holds indices outside the {ny}×{nx} grid (0 … {ny * nx - 1}): {cell.min()} … {cell.max()}"
        )
    boxes = [checks.number(b, "boxes[]", lo=1, integer=True) for b in np.atleast_1d(boxes).tolist()]
    maps, fracs, ent, wd = {}, {}, {}, {}
    for key, df in split_points(lifetimes):
        df = df.sort_values("traj_id")
        ids = df["traj_id"].to_numpy(dtype=np.int64)
        if ids.size and (ids.min() < 0 or ids.max() >= cell.size):
            raise ConfigError(f"traj_id {ids.max()} has no cell: cell holds {cell.size} initial conditions")
        oc = df["outcome"].astype(str).to_numpy()
        code = np.full(ids.size, TRAPPED_BASIN, dtype=np.int64)
        esc = oc == "escaped"
        code[esc] = df["exit_channel"].to_numpy(dtype=float, na_value=-1)[esc].astype(np.int64)
        code[oc == "settled"] = SETTLED_BASIN
        img = np.full(ny * nx, OUTSIDE_BASIN, dtype=np.int64)
        img[cell[ids]] = code
        lab = img.reshape(ny, nx)
        maps[key] = lab
        fracs[key] = basin_fractions(lab, outside=OUTSIDE_BASIN)
        ent[key] = basin_entropy_table(lab, boxes, outside=OUTSIDE_BASIN)
        present = [int(b) for b, f in zip(fracs[key].basins, fracs[key].frac) if f >= 0.005]
        wd[key] = wada_merging(lab, basins=present, outside=OUTSIDE_BASIN) if wada and len(present) >= 3 else None
    return BasinMeasures(maps, fracs, ent, wd, None if extent is None else tuple(float(v) for v in extent))
