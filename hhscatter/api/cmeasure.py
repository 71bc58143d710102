"""The c-measure: κ from the c-measure of a run's section crossings, its section points, their distances to a reference set."""

from __future__ import annotations

import dataclasses
import math
import os
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.api import checks
from hhscatter.api.plotting import _axes
from hhscatter.api.points import (
    _key_columns,
    _label,
    _PointRows,
    _same_point,
    _sorted_keys,
    _split_like,
    split_points,
)
from hhscatter.api.rates import DISSIPATIVE_NOTE, EscapeRates, escape_rates
from hhscatter.api.runs import run_scene
from hhscatter.data.params import checked_value, same_run
from hhscatter.data.read import read_lifetimes
from hhscatter.errors import ConfigError

#: the columns of a sections table the c-measure reads
SECTION_COLUMNS = ("traj_id", "t")

if TYPE_CHECKING:  # annotations only: pandas and matplotlib are imported when a function runs
    import pandas
    from matplotlib.axes import Axes


@dataclass(frozen=True)
class CMeasureRates(_PointRows):
    """Result of :func:`kappa_cmeasure`: κ from the c-measure beside κ from P(t), per grid point.

    ``.to_frame()`` columns: energy, gamma, n, kappa_cm, kappa_cm_err (bootstrap over orbits, 1σ), mu_exit
    (μ_c(𝓔)), n_samples, n_exit, n_undetermined, t_from, t_to (the sampling window), t_record_end, kappa_pt,
    kappa_pt_err (κ from P(t) of the same run, :func:`escape_rates`), note (why κ is NaN, else empty).

    Attributes
    ----------
    rows : dict
        (energy, gamma) → dict of the point's numbers (the columns of :meth:`to_frame`).
    """

    def plot(self, ax: Axes | None = None, **errorbar_kwargs: Any) -> Axes:
        """Draw κ from the c-measure and from P(t) against E0; returns the axes."""
        df = self.to_frame()
        ax = _axes(ax)
        kw = {"capsize": 3, **errorbar_kwargs}
        ax.errorbar(df["energy"], df["kappa_pt"], yerr=df["kappa_pt_err"], fmt="o", label="κ from P(t)", **kw)
        ax.errorbar(
            df["energy"],
            df["kappa_cm"],
            yerr=df["kappa_cm_err"],
            fmt="D",
            mfc="none",
            label="κ from the c-measure",
            **kw,
        )
        ax.set_xlabel("E0")
        ax.set_ylabel("κ")
        ax.legend()
        return ax


def kappa_cmeasure_tables(
    lifetimes: pandas.DataFrame,
    sections: pandas.DataFrame,
    *,
    window: tuple[float, float] | None = None,
    t_max: float | None = None,
    t_from: float | None = None,
    t_to: float | None = None,
    rec_efolds: float = 2.0,
    margin: float = 40.0,
    n_boot: int = 200,
    seed: int = 0,
) -> CMeasureRates:
    """κ from the c-measure of the true-time map, per conservative grid point of a run, beside κ from P(t).

    Solves ∫_Ω e^{κT} dμ_c = 1 + μ_c(𝓔), Eq. (eqn:kappa_cmeasure_truetime), with every section crossing of
    the run in a late window [t_from, t_to] as a sample point of μ_c, T its time to the orbit's next crossing
    and 𝓔 the crossings after which the orbit leaves (:func:`~hhscatter.analysis.survival.cmeasure.kappa_from_cmeasure`,
    bootstrap over orbits). The run's requirements are checked here, from its section window: its sections
    must hold *every* crossing (a ``SectionWindow`` without energy filter, not ``first_only``) and the
    recording must go on after t_to (its end, ``t_record_end`` = min(window ``t_to``, ``t_max``), closes the
    sample: a crossing whose next one would come after it is undetermined, dropped and counted). Orbits still
    inside at ``t_max`` are left out when ``t_max`` > t_record_end (they sit on KAM tori and are not part of the
    c-measure of the chaotic saddle); run with t_max ≫ t_record_end for that. ``hhscatter.kappa_cmeasure(run)``
    reads all of this from a run directory (:func:`kappa_cmeasure`).

    Parameters
    ----------
    lifetimes, sections : DataFrame
        :func:`hhscatter.read_lifetimes` and :func:`hhscatter.read_sections` of one run (a scene or a grid;
        γ > 0 points get NaN and a note).
    window : SectionWindow or dict, optional
        The section window the run recorded (``Scene.sections``). Read from the data (the run's scene.json,
        which the readers attach); a value passed here that contradicts it raises ValueError.
    t_max : float, optional
        The run's ``t_max`` (time units); read from the data like ``window``.
    t_from, t_to : float, optional
        The sampling window (time units). Default per point: t_from = max(window start, ⌈τ0 + rec_efolds/κ⌉)
        with τ0, κ from P(t) of the same point, t_to = t_record_end − ``margin``.
    rec_efolds : float
        e-folds of P(t) after τ0 before sampling starts (the ensemble relaxes towards μ_c).
    margin : float
        Time units kept between t_to and the end of the recording (longer than almost every return time).
    n_boot : int
        Bootstrap replicates over orbits for ``kappa_cm_err``.
    seed : int
        Seed of the bootstrap.

    Returns
    -------
    CMeasureRates
        ``.to_frame()`` one row per point (κ_cm ± err, μ_c(𝓔), the window, κ from P(t) ± err),
        ``.plot(ax=)`` both κ against E0.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> window = hhscatter.SectionWindow(t_from=10.0, t_to=70.0)       # every crossing in [10, 70]
    >>> scene = hhscatter.Scene(energy=0.3, n=400, seed=1, t_max=1000.0, sections=window)
    >>> run = tempfile.mkdtemp()
    >>> _ = hhscatter.simulate(scene, run, overwrite=True, workers=1, progress=False)
    >>> lt, sec = hhscatter.read_lifetimes(run), hhscatter.read_sections(run)
    >>> from hhscatter.api import kappa_cmeasure_tables
    >>> row = kappa_cmeasure_tables(lt, sec, window=window, t_max=1000.0).to_frame().iloc[0]
    >>> bool(abs(row.kappa_cm - row.kappa_pt) < 3 * (row.kappa_cm_err + row.kappa_pt_err))
    True
    """

    checks.frame(lifetimes, "lifetimes", needs=("t_end", "outcome"))
    checks.frame(
        sections, "sections", needs=SECTION_COLUMNS, what="a sections table", reader="hhscatter.read_sections(run)"
    )
    for name, v, lo in (("rec_efolds", rec_efolds, 0.0), ("margin", margin, 0.0)):
        checks.number(v, name, lo=lo)
    checks.number(n_boot, "n_boot", lo=0, integer=True)
    checks.number(seed, "seed", lo=0, integer=True)
    for name, v in (("t_from", t_from), ("t_to", t_to), ("t_max", t_max)):
        if v is not None:
            checks.number(v, name, lo=0.0)
    same_run(lifetimes, sections, what="the lifetimes and sections tables")
    window = checked_value(lifetimes, "sections", _window_dict(window), what="the section window", name="window")
    t_max = checked_value(lifetimes, "t_max", t_max, what="t_max")
    if window is None or t_max is None:
        raise ConfigError("pass window= and t_max= of the run (the tables carry no record of their run)")
    window = _checked_cmeasure_window(window)
    t_max = float(t_max)
    t_record_end = min(float(window.get("t_to", math.inf)), t_max)
    lt, sec = lifetimes, sections
    rates = escape_rates(lt) if any(k[1] == 0 for k, _ in split_points(lt)) else EscapeRates({}, {}, {})
    keys = [k for k, _ in split_points(lt)]
    sec_by = _split_like(sec, keys, what="sections table")
    from hhscatter.analysis.survival.cmeasure import (  # deferred: scipy loads on first use
        cmeasure_sample_from_sections,
    )

    rows = {}
    for key, df in split_points(lt):

        def sample(t0, t1, key=key, df=df):
            return cmeasure_sample_from_sections(
                sec_by.get(key, sec.iloc[:0]),
                df,
                t0,
                t1,
                t_record_end=t_record_end,
                drop_censored=t_max > t_record_end,
                with_orbits=True,
            )

        rows[key] = _cmeasure_point_row(
            key,
            df,
            sample,
            rates,
            window,
            t_max,
            t_record_end,
            t_from,
            t_to,
            rec_efolds,
            margin,
            n_boot,
            seed,
        )
    return CMeasureRates(rows)


def _window_dict(window):
    """A SectionWindow as the dict of its fields (None and dicts as given)."""
    return dataclasses.asdict(window) if window is not None and dataclasses.is_dataclass(window) else window


def _checked_cmeasure_window(window) -> dict:
    """The run's section window as a dict, refused unless it records every crossing (no filter, not first_only)."""
    if window is not None and dataclasses.is_dataclass(window):
        window = dataclasses.asdict(window)
    if not window:
        raise ConfigError(
            "the run recorded no sections; simulate with sections=SectionWindow(t_from=…, t_to=…) "
            "(every crossing, no energy filter)"
        )
    if (
        window.get("first_only")
        or math.isfinite(window.get("e_min", -math.inf))
        or math.isfinite(window.get("e_max", math.inf))
    ):
        raise ConfigError(
            f"the c-measure needs every section crossing; the run's window {window} filters them "
            "(first_only or e_min/e_max): record with a plain SectionWindow(t_from, t_to)"
        )
    return window


def _sampling_window(key, rates, window, t_record_end, t_from, t_to, rec_efolds, margin):
    """(t0, t1) of a point's c-measure sample (time units), or None without a κ from P(t)."""
    r = rates.results.get(key)
    if r is None:
        return None
    t0 = (
        float(t_from)
        if t_from is not None
        else max(float(window.get("t_from", 0.0)), math.ceil(r.tau0 + rec_efolds / r.kappa))
    )
    t1 = float(t_to) if t_to is not None else t_record_end - margin
    return t0, t1


def _cmeasure_point_row(
    key, df, sample, rates, window, t_max, t_record_end, t_from, t_to, rec_efolds, margin, n_boot, seed
) -> dict:
    """One grid point's row of :func:`kappa_cmeasure_tables`: its sampling window (time units) from τ0 and κ of
    P(t), the c-measure sample of its crossings in it (``sample(t0, t1)`` → the return times, exits, undetermined
    count and their orbits, :func:`~hhscatter.analysis.survival.cmeasure.cmeasure_sample_from_sections`),
    κ_cm ± err (1/time) beside κ from P(t), or a note."""
    from hhscatter.analysis.survival.cmeasure import kappa_from_cmeasure  # deferred: scipy loads on first use

    row = {
        **_key_columns(key),
        "n": len(df),
        "kappa_cm": math.nan,
        "kappa_cm_err": math.nan,
        "mu_exit": math.nan,
        "n_samples": 0,
        "n_exit": 0,
        "n_undetermined": 0,
        "t_from": math.nan,
        "t_to": math.nan,
        "t_record_end": t_record_end,
        "kappa_pt": math.nan,
        "kappa_pt_err": math.nan,
        "note": "",
    }
    r = rates.results.get(key)
    if r is None:
        row["note"] = DISSIPATIVE_NOTE if key[1] > 0 else rates.notes.get(key, "no κ from P(t)")
        return row
    row.update(kappa_pt=r.kappa, kappa_pt_err=r.kappa_err)
    t0, t1 = _sampling_window(key, rates, window, t_record_end, t_from, t_to, rec_efolds, margin)
    row.update(t_from=t0, t_to=t1)
    if not t1 > t0 or t0 < float(window.get("t_from", 0.0)) or t1 > t_record_end:
        row["note"] = (
            f"sampling window [{t0:g}, {t1:g}] does not fit the recording [{window.get('t_from', 0)}, "
            f"{t_record_end:g}]: record sections until ≥ {t0 + margin + 2 / r.kappa:.0f}"
        )
        return row
    with counted("api.cmeasure"):
        T, n_exit, n_und, orb, exit_orb = sample(t0, t1)
    if T.size + n_exit == 0:
        row["note"] = "no section crossing in the sampling window"
        return row
    k = kappa_from_cmeasure(T, n_exit, orbits=orb, exit_orbits=exit_orb, n_boot=n_boot, rng=seed)
    row.update(
        kappa_cm=k.kappa,
        kappa_cm_err=k.kappa_err,
        mu_exit=k.mu_exit,
        n_samples=k.n_samples,
        n_exit=k.n_exit,
        n_undetermined=n_und,
    )
    return row


def kappa_cmeasure(run: str | os.PathLike[str], **kwargs: Any) -> CMeasureRates:
    """κ from the c-measure of a run's section crossings, per conservative grid point, beside κ from P(t).

    Parameters
    ----------
    run : str or Path
        A run directory of :func:`hhscatter.simulate` whose scene recorded every section crossing
        (``sections=SectionWindow(t_from=…, t_to=…)``, no energy filter, not ``first_only``).
    **kwargs
        ``t_from``, ``t_to``, ``rec_efolds``, ``margin``, ``n_boot``, ``seed`` of
        :func:`kappa_cmeasure_tables`, which does the work (its docstring has the method).

    Returns
    -------
    CMeasureRates
        ``.to_frame()`` one row per point (κ_cm ± err, μ_c(𝓔), the sampling window, κ from P(t) ± err),
        ``.plot(ax=)`` both κ against E0.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> scene = hhscatter.Scene(energy=0.3, n=400, seed=1, t_max=1000.0,
    ...                         sections=hhscatter.SectionWindow(t_from=10.0, t_to=70.0))
    >>> run = tempfile.mkdtemp()
    >>> _ = hhscatter.simulate(scene, run, overwrite=True, workers=1, progress=False)
    >>> hhscatter.kappa_cmeasure(run).to_frame()[["energy", "t_record_end", "note"]].values.tolist()
    [[0.3, 70.0, '']]
    """
    checks.run_dir(run)
    unknown = sorted(set(kwargs) - {"t_from", "t_to", "rec_efolds", "margin", "n_boot", "seed"})
    if unknown:
        raise ConfigError(
            f"kappa_cmeasure has no option {unknown[0]!r}; its options: t_from, t_to, rec_efolds, margin, n_boot, "
            "seed (window and t_max are read from the run)"
        )
    scene = run_scene(run)
    if not scene.get("sections"):
        raise ConfigError(
            f"{run}: the run recorded no sections; simulate with sections=SectionWindow(t_from=…, "
            "t_to=…) (every crossing, no energy filter)"
        )
    opts = {"t_from": None, "t_to": None, "rec_efolds": 2.0, "margin": 40.0, "n_boot": 200, "seed": 0, **kwargs}
    for name in ("rec_efolds", "margin"):
        checks.number(opts[name], name, lo=0.0)
    checks.number(opts["n_boot"], "n_boot", lo=0, integer=True)
    checks.number(opts["seed"], "seed", lo=0, integer=True)
    for name in ("t_from", "t_to"):
        if opts[name] is not None:
            checks.number(opts[name], name, lo=0.0)
    window = _checked_cmeasure_window(scene["sections"])
    t_max = float(scene["t_max"])
    t_record_end = min(float(window.get("t_to", math.inf)), t_max)
    grid = any(isinstance(scene.get(k), list) for k in ("energy", "gamma"))
    # the lifetimes: the columns a point, κ from P(t) and the sample's fates need, outcome as categories
    lt = read_lifetimes(
        run, columns=["traj_id", "t_end", "outcome", "gamma", "energy" if grid else "e0"], categorical=True
    )
    points = split_points(lt)
    keys = [k for k, _ in points]
    conservative = [k for k in keys if k[1] == 0]
    rates = escape_rates(lt[lt["gamma"] == 0]) if conservative else EscapeRates({}, {}, {})
    args = (t_record_end, opts["t_from"], opts["t_to"], opts["rec_efolds"], opts["margin"])
    windows = {k: w for k in keys if (w := _sampling_window(k, rates, window, *args)) is not None}
    samples = _streamed_samples(run, dict(points), windows, keys, grid, t_record_end, t_max > t_record_end)
    rows = {}
    for key, df in points:
        rows[key] = _cmeasure_point_row(
            key,
            df,
            lambda t0, t1, key=key: samples[key],
            rates,
            window,
            t_max,
            t_record_end,
            opts["t_from"],
            opts["t_to"],
            opts["rec_efolds"],
            opts["margin"],
            opts["n_boot"],
            opts["seed"],
        )
    return CMeasureRates(rows)


def _streamed_samples(run, lifetimes: dict, windows: dict, keys, grid: bool, t_record_end, drop_censored) -> dict:
    """{key: the c-measure sample of the point's crossings in its window} from the run's sections table read part
    by part (only ``traj_id``, ``t`` and the point columns of the crossings at t ≥ the earliest window start):
    memory is one part's late crossings plus the samples, whatever N. Parts are orbit ranges, so each part's
    sample is exact; concatenated and put in orbit order it is the sample of the whole table."""
    import pyarrow.dataset as ds  # deferred: pyarrow loads on first use

    from hhscatter.analysis.survival.cmeasure import (  # deferred: scipy loads on first use
        cmeasure_sample_from_sections,
    )
    from hhscatter.data.read import iter_part_frames  # deferred: pyarrow loads on first use

    fits = {k: w for k, w in windows.items() if w[1] > w[0]}
    acc = {k: ([], 0, 0, [], []) for k in fits}
    if fits:
        columns = ["traj_id", "t", *(("point_energy", "point_gamma") if grid else ())]
        start = min(w[0] for w in fits.values())
        for part in iter_part_frames(run, "sections", columns, ds.field("t") >= start):
            if not len(part):
                continue
            for key, sec in _split_like(part, keys, what="sections table").items():
                if key not in fits or not len(sec):
                    continue
                lt = lifetimes[key]
                lt = lt[lt["traj_id"].isin(sec["traj_id"].unique())]
                T, n_exit, n_und, orb, exit_orb = cmeasure_sample_from_sections(
                    sec, lt, *fits[key], t_record_end=t_record_end, drop_censored=drop_censored, with_orbits=True
                )
                Ts, ne, nu, orbs, exits = acc[key]
                acc[key] = (Ts + [(orb, T)], ne + n_exit, nu + n_und, orbs, exits + [exit_orb])
    out = {}
    for key, (Ts, n_exit, n_und, _, exits) in acc.items():
        orb = np.concatenate([o for o, _ in Ts]) if Ts else np.empty(0, np.int64)
        T = np.concatenate([t for _, t in Ts]) if Ts else np.empty(0)
        order = np.argsort(orb, kind="stable")  # the whole table's order: by orbit, then time
        exit_orb = np.sort(np.concatenate(exits)) if exits else np.empty(0, np.int64)
        out[key] = (T[order], n_exit, n_und, orb[order], exit_orb)
    empty = (np.empty(0), 0, 0, np.empty(0, np.int64), np.empty(0, np.int64))
    return {k: out.get(k, empty) for k in windows}


@dataclass(frozen=True)
class CMeasurePoints:
    """Result of :func:`cmeasure_points`: section points (x, y, px, py, t) per grid point.

    Attributes
    ----------
    points : dict
        (energy, gamma) → DataFrame of the selected section crossings (traj_id, t, x, y, px, py, energy).
    """

    points: dict

    def __getitem__(self, key):
        if key in self.points:
            return self.points[key]
        hits = [k for k in self.points if _same_point(k, key)] if isinstance(key, tuple) else []
        if len(hits) == 1:
            return self.points[hits[0]]
        raise KeyError(f"no point {key!r}; points: {list(self.points)}")

    def to_frame(self) -> pandas.DataFrame:
        """Every selected crossing in one DataFrame: point_energy, point_gamma, traj_id, t, x, y, …"""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.concat(
            [p.assign(point_energy=k[0], point_gamma=k[1]) for k, p in self.points.items()], ignore_index=True
        )

    def plot(
        self, ax: Axes | None = None, *, key: tuple[float, float] | None = None, s: float = 0.5, **scatter_kwargs: Any
    ) -> Axes:
        """Draw the points in (x, y), one colour per grid point (or only point ``key``); returns the axes."""
        ax = _axes(ax)
        for k in [key] if key is not None else _sorted_keys(self.points):
            p = self[k]
            ax.scatter(p["x"], p["y"], s=s, label=f"{_label(k)} ({len(p)})", **scatter_kwargs)
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.legend(markerscale=8)
        return ax


def cmeasure_points(
    sections: pandas.DataFrame,
    *,
    t_from: float,
    t_to: float = math.inf,
    first_only: bool = False,
    e_min: float = -math.inf,
    e_max: float = math.inf,
    lifetimes: pandas.DataFrame | None = None,
) -> CMeasurePoints:
    """Points of the c-measure on the section ṙ = 0, φ̇ > 0: the crossings of the survivors after ``t_from``.

    With ``first_only=False`` every crossing in [t_from, t_to] (the flux measure, paper Fig. 1b); with
    ``first_only=True`` the first crossing of each orbit at t ≥ t_from (the "first intersection for t ≥ t*"
    of the paper's Fig. 5a, :func:`~hhscatter.analysis.geometry.distance.first_crossings`), then kept if its energy is
    in [e_min, e_max] (Fig. 5b). The run must have recorded every crossing from t_from on.

    Parameters
    ----------
    sections : DataFrame
        :func:`hhscatter.read_sections` of a run.
    t_from, t_to : float
        Orbit-time window (time units).
    first_only : bool
        One point per orbit (its first crossing at t ≥ t_from).
    e_min, e_max : float
        Energy band at the crossing.
    lifetimes : DataFrame, optional
        The run's lifetimes, to name the point of a plain run (whose sections have no point columns).

    Returns
    -------
    CMeasurePoints
        ``.to_frame()`` the points, ``.plot(ax=)`` them in (x, y); ``[key]`` one point's DataFrame.

    Examples
    --------
    >>> import pandas as pd, hhscatter
    >>> sec = pd.DataFrame({"traj_id": [1, 1, 2, 2], "t": [5.0, 25.0, 22.0, 30.0], "x": [0.1, 0.2, 0.3, 0.4],
    ...                     "y": 0.0, "px": 0.0, "py": 0.0, "energy": 0.3, "point_energy": 0.3, "point_gamma": 0.0})
    >>> pts = hhscatter.cmeasure_points(sec, t_from=20.0, first_only=True)
    >>> pts[(0.3, 0.0)]["x"].tolist()
    [0.2, 0.3]
    """
    from hhscatter.analysis.geometry.distance import first_crossings  # deferred: pandas, pyarrow load on first use

    checks.frame(
        sections,
        "sections",
        needs=("t", "x", "y", "traj_id"),
        what="a sections table",
        reader="hhscatter.read_sections(run)",
    )
    t_from = checks.number(t_from, "t_from", lo=0.0)
    t_to = checks.number(t_to, "t_to", lo=t_from, finite=False)
    e_min = checks.number(e_min, "e_min", finite=False)
    e_max = checks.number(e_max, "e_max", lo=e_min, finite=False)
    keys = [k for k, _ in split_points(lifetimes)] if lifetimes is not None else None
    out = {}
    for key, df in _split_like(sections, keys, what="sections table").items():
        df = df[df["t"] <= t_to]
        if first_only:
            df = first_crossings(df, t_from, e_min=e_min, e_max=e_max)
        else:
            df = df[df["t"] >= t_from]
            if "energy" in df.columns:
                df = df[(df["energy"] >= e_min) & (df["energy"] <= e_max)]
        out[key] = df.drop(columns=["point_energy", "point_gamma"], errors="ignore").reset_index(drop=True)
    return CMeasurePoints(out)


@dataclass(frozen=True)
class CMeasureDistances:
    """Result of :func:`cmeasure_distances`: distances of each point's section points to a reference set.

    Attributes
    ----------
    tables : dict
        (energy, gamma) → :func:`~hhscatter.analysis.geometry.distance.distance_vs_scale` table (one row per box side).
    scales : dict
        (energy, gamma) → agreement scale ε* (:func:`~hhscatter.analysis.geometry.distance.agreement_scale`), or NaN.
    """

    tables: dict
    scales: dict

    def to_frame(self) -> pandas.DataFrame:
        """The distances as a DataFrame: energy, gamma, box, hellinger, tv, …_noise, …_excess, agreement_scale."""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.concat(
            [
                self.tables[k].assign(energy=k[0], gamma=k[1], agreement_scale=self.scales[k])
                for k in _sorted_keys(self.tables)
            ],
            ignore_index=True,
        )

    def plot(self, ax: Axes | None = None, *, kind: str = "hellinger", **plot_kwargs: Any) -> Axes:
        """Draw the distance and its split-half noise floor against the box side; returns the axes."""
        ax = _axes(ax)
        for k in _sorted_keys(self.tables):
            d = self.tables[k]
            col = f"{kind}_pq" if f"{kind}_pq" in d else kind
            (line,) = ax.plot(d["box"], d[col], "o-", label=_label(k), **plot_kwargs)
            if f"{kind}_noise" in d:
                ax.plot(d["box"], d[f"{kind}_noise"], ":", color=line.get_color())
        ax.set_xscale("log")
        ax.set_xlabel("box side ε")
        ax.set_ylabel(f"{kind} distance (dotted: noise floor)")
        ax.legend()
        return ax


def cmeasure_distances(
    points: CMeasurePoints,
    reference: pandas.DataFrame | np.ndarray,
    boxes: tuple[float, ...] = (0.4, 0.2, 0.1, 0.05),
    *,
    n_splits: int = 8,
    seed: int = 0,
    m: int | None = None,
) -> CMeasureDistances:
    """Hellinger and total-variation distances between each point's section points and a reference set, vs scale.

    Box histograms of the two sets over a common partition at each box side ε, the distance of the full sets,
    and, at a common sample size m, the split-half noise floor (the distance two halves of one set have) and the
    excess over it (:func:`~hhscatter.analysis.geometry.distance.distance_vs_scale`). The agreement scale ε* is the
    smallest box side at which the excess is within noise (:func:`~hhscatter.analysis.geometry.distance.agreement_scale`).
    Beyond the paper (study fig5 compares dissipative points after t* with the conservative c-measure).

    Parameters
    ----------
    points : CMeasurePoints
        The sets to compare (every point of it).
    reference : DataFrame or array (n, 2)
        The reference points (columns x, y), e.g. ``conservative[(0.3, 0.0)]`` of another
        :func:`cmeasure_points`.
    boxes : sequence of float
        Box sides ε (position units).
    n_splits, seed, m
        Split-half repetitions, their seed, the common sample size of the split halves (default: the smallest
        ⌊min(n_P, n_Q)/2⌋ over the points, one m for all, so that their distances and noise floors compare).

    Returns
    -------
    CMeasureDistances
        ``.to_frame()`` one row per (point, box side), ``.plot(ax=)`` distance against ε. A point with fewer
        than 4 section points is left out, with a ``UserWarning`` naming it.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> rng = np.random.default_rng(1)
    >>> ref = pd.DataFrame(rng.uniform(-1, 1, (4000, 2)), columns=["x", "y"])
    >>> same = pd.DataFrame(rng.uniform(-1, 1, (4000, 2)), columns=["x", "y"]).assign(
    ...     point_energy=0.3, point_gamma=0.01, t=50.0, traj_id=np.arange(4000))
    >>> d = hhscatter.cmeasure_distances(hhscatter.cmeasure_points(same, t_from=0.0), ref, boxes=[1.0, 0.5])
    >>> bool((d.to_frame()["hellinger_excess"].abs() < 0.05).all())
    True
    """
    from hhscatter.analysis.geometry.distance import (  # deferred: pandas, pyarrow load on first use
        agreement_scale,
        distance_vs_scale,
    )
    from hhscatter.analysis.geometry.distance import points as xy  # deferred: pandas, pyarrow load on first use

    checks.result(points, "points", (CMeasurePoints,), "hhscatter.cmeasure_points")
    if hasattr(reference, "columns"):
        checks.frame(reference, "reference", needs=("x", "y"), what="section points", reader="cmeasure_points")
        Q = xy(reference)
    else:
        try:
            Q = np.asarray(reference, dtype=float)
        except (TypeError, ValueError):
            Q = np.empty((0, 0))
        if Q.ndim != 2 or Q.shape[1] != 2 or not len(Q) or not np.isfinite(Q).all():
            raise ConfigError(
                f"reference must be a DataFrame (x, y) or a finite (n, 2) array, got {checks.describe(reference)}"
            )
    boxes = [checks.number(b, "boxes[]", lo=0.0, lo_open=True) for b in np.atleast_1d(boxes).tolist()]
    if not boxes:
        raise ConfigError("boxes must hold at least one box side")
    n_splits = checks.number(n_splits, "n_splits", lo=0, integer=True)
    seed = checks.number(seed, "seed", lo=0, integer=True)
    if m is not None:
        m = checks.number(m, "m", lo=1, integer=True)
    tables, scales, few = {}, {}, []
    if m is None and n_splits > 0:  # one sample size for every point, so their noise floors compare
        sizes = [min(len(df), len(Q)) // 2 for df in points.points.values() if len(df) >= 4]
        m = min(sizes) if sizes else None
    for key, df in points.points.items():
        if n_splits > 0 and len(df) < 4:  # the split-half noise floor needs two points per half
            few.append(f"{_label(key)} ({len(df)} points)")
            continue
        t = distance_vs_scale(xy(df), Q, boxes, n_splits=n_splits, seed=seed, m=m)
        tables[key] = t
        eps = agreement_scale(t) if n_splits >= 2 else None
        scales[key] = math.nan if eps is None else float(eps)
    if few:
        warnings.warn(f"cmeasure_distances: left out, too few points: {'; '.join(few)}", UserWarning, stacklevel=2)
    return CMeasureDistances(tables, scales)
