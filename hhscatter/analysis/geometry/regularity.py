"""Regular and chaotic orbits told apart: a finite-time Lyapunov exponent from a shadow orbit.

An orbit on a KAM torus (regular) and its neighbour at distance d0 separate linearly in time (the shear of the
tori), an orbit in the chaotic sea exponentially, d(t) ≈ d0 e^{λt}. The indicator here is the two-orbit
(shadow) estimate of the finite-time Lyapunov exponent: every orbit is integrated twice by the engine, once from
its initial condition and once from a shadow displaced by d0 on the same energy shell
(:func:`shadow_ics`), and the two are compared at their first crossing of the surface of section
(ṙ = 0, φ̇ > 0) at orbit time t ≥ t_from (:func:`shadow_indicator`):

    G = ‖Δ(x, y, p_x, p_y)‖ / d0,      λ_T = ln(G) / t.

A regular orbit has G of order 1 + (shear)·t (at most ~10³ over t ≲ 2000 for the systems here), a chaotic one
e^{λt} until it saturates at the size of the chaotic sea (≈ 0.1–1, i.e. G ≈ 10⁸–10⁹ for d0 = 10⁻⁹). An orbit is
called regular when G < ``g_max`` (default 10⁴: ln G = 9.2, so a chaotic orbit with λ > 9.2/t is told apart;
λ ≳ 0.005 at t = 1900). An orbit whose shadow leaves (escapes) while it stays, or the reverse, is chaotic. The
threshold is validated against orbits whose type an independent integration (scipy, variational equations,
renormalised tangent vector) fixes, among them orbits at island edges whose growth lies between a torus' and the
saturated sea's. :func:`threshold_systematic` gives the systematic of
the threshold choice (the fraction's largest shift with the threshold a decade either side).

A second, independent indicator is the variational FTLE (:func:`variational_indicator`): the log-stretch Λ of a
tangent vector carried along the orbit by the linearised flow (the engine's tangent dynamics, a scene with
``tangent = true``), λ_T = Λ(T)/T over [0, T]. On a torus Λ grows like ln t (the shear), so λ_T → 0 like
ln(t)/t; in the chaotic sea λ_T → λ. An orbit is labelled regular below ``ftle_regular``, chaotic above
``ftle_chaotic`` (or when it escapes before T: no torus leaves), undecided between.
:func:`indicator_systematic` compares the two indicators on a labelled subset of the orbits whose shadow growth
lies in the band between tori and the saturated sea, and scales the disagreements to the whole band.

Conventions: the separation is Euclidean in (x, y, p_x, p_y) (length and momentum units alike: ω = 1); the
shadow differs by +d0 in x with both momenta scaled by one factor that keeps H(x, y, p_x, p_y) = E (−d0 where
+d0 leaves no kinetic energy). Every integration is the engine's (a run from an IC table); this module only
prepares the shadow ICs and reads the two runs' section tables.

Examples
--------
>>> import numpy as np, pandas as pd
>>> base = pd.DataFrame({"traj_id": [0, 1], "t": [1900.5, 1901.0], "x": [0.1, 0.2], "y": [0.0, 0.1],
...                      "px": [0.3, 0.2], "py": [0.1, 0.0]})
>>> shadow = base.assign(x=[0.1 + 1e-7, 0.5])       # orbit 0 stayed close (G = 100), orbit 1 did not
>>> ind = shadow_indicator(base, shadow, [0, 1], [1e-9, 1e-9], 1900.0)
>>> ind["regular"].tolist()
[True, False]
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

SHADOW_DELTA = 1e-9  # initial displacement of the shadow orbit (length units)
G_MAX = 1e4  # separation growth below which an orbit is called regular
INDICATOR = "shadow FTLE"  # the indicator's name in records


def shadow_ics(states, potential, delta: float = SHADOW_DELTA) -> tuple[np.ndarray, np.ndarray]:
    """shadow_ics(states, potential, delta=1e-9) -> (shadow states (n, 4), d0 (n,)).

    The shadow of each initial state (x, y, p_x, p_y) on the same energy shell: x + δ (x − δ where x + δ leaves no
    kinetic energy), both momenta scaled by √((E − V(x ± δ, y)) / K), so H is unchanged to rounding; d0 is the
    Euclidean distance of the two states (≈ δ; length units).

    Parameters
    ----------
    states : array (n, 4)
        Initial states (x, y, p_x, p_y) of the base orbits.
    potential : callable
        V(x, y) of the system (``System.potential``), vectorised.
    delta : float
        Displacement in x (length units), default 1e-9.

    Examples
    --------
    >>> s = np.array([[0.1, 0.0, 0.3, 0.2]])
    >>> V = lambda x, y: 0.5 * (x**2 + y**2)
    >>> sh, d0 = shadow_ics(s, V)
    >>> bool(abs(0.5 * (sh[0, 2]**2 + sh[0, 3]**2) + V(sh[0, 0], sh[0, 1]) - 0.07) < 1e-15)
    True
    """
    check.numbers(states, "states")
    check.function(potential, "potential")
    delta = check.number(delta, "delta", positive=True)
    s = np.asarray(states, dtype=float)
    if s.ndim != 2 or s.shape[1] != 4:
        raise ConfigError(f"states must be (n, 4) (x, y, px, py), got shape {s.shape}")
    x, y, px, py = s.T
    K = 0.5 * (px**2 + py**2)
    E = K + potential(x, y)
    out = np.full_like(s, np.nan)
    for sign in (-1.0, 1.0):  # +δ wherever it leaves kinetic energy, −δ elsewhere
        xs = x + sign * delta
        K2 = E - potential(xs, y)
        ok = (K2 > 0) & (K > 0)
        f = np.sqrt(np.where(ok, K2, 1.0) / np.where(K > 0, K, 1.0))
        out[ok] = np.column_stack([xs, y, px * f, py * f])[ok]
    bad = ~np.isfinite(out[:, 0])
    if bad.any():
        raise ConfigError(f"no shadow on the energy shell for {int(bad.sum())} state(s) (no kinetic energy at x ± δ)")
    return out, np.linalg.norm(out - s, axis=1)


def shadow_indicator(
    base_sections: pd.DataFrame, shadow_sections: pd.DataFrame, traj_ids, d0, t_from: float, *, g_max: float = G_MAX
) -> pd.DataFrame:
    """shadow_indicator(base_sections, shadow_sections, traj_ids, d0, t_from, g_max=1e4) -> DataFrame per orbit.

    For each orbit of ``traj_ids`` (shadows share the base's traj_id), its first section crossing at t ≥ ``t_from``
    in either table (:func:`hhscatter.analysis.geometry.distance.first_crossings`) and the growth
    G = ‖Δ(x, y, p_x, p_y)‖/d0 there. Columns: traj_id, t (the base's crossing, time units), growth, ftle
    (ln G / t, 1/time), kind ('regular' G < g_max, 'chaotic' otherwise or when exactly one of the two crosses,
    'none' when neither crosses at t ≥ t_from: the orbit left before, or never crosses the section), regular.

    Parameters
    ----------
    base_sections, shadow_sections : DataFrame
        The engine's sections tables (traj_id, t, x, y, px, py) of the base and the shadow runs, holding every
        crossing at t ≥ t_from (a section window that starts at or before t_from; ``first_only`` allowed).
    traj_ids, d0 : array (n,)
        The orbits to classify and their initial separations (:func:`shadow_ics`).
    t_from : float
        Time (time units) from which the first crossing is taken.
    g_max : float
        Separation growth below which an orbit is regular.

    Examples
    --------
    Three orbits and their shadows started d0 = 1e-8 apart, first crossings after t = 5: orbit 0's pair is 1e-6
    apart at t = 10 (G = 100, regular; ftle = ln 100 / 10 = 0.4605), orbit 1's 0.2 apart (G = 2e7, chaotic),
    orbit 2 crosses only before t = 5.

    >>> cols = {"traj_id": [0, 1, 2], "t": [10.0, 10.0, 2.0], "x": 0.1, "y": 0.0, "px": 0.0, "py": 0.5}
    >>> base = pd.DataFrame(cols)
    >>> shadow = pd.DataFrame(cols).assign(x=[0.1 + 1e-6, 0.3, 0.1])
    >>> out = shadow_indicator(base, shadow, [0, 1, 2], 1e-8, t_from=5.0)
    >>> out["kind"].tolist(), out["growth"].round(1).tolist(), round(float(out["ftle"][0]), 4)
    (['regular', 'chaotic', 'none'], [100.0, 20000000.0, nan], 0.4605)
    """
    from hhscatter.analysis.geometry.distance import first_crossings  # deferred: pandas loads on first use

    cols = ["traj_id", "t", "x", "y", "px", "py"]
    check.table(base_sections, "base_sections", cols, min_rows=0)
    check.table(shadow_sections, "shadow_sections", cols, min_rows=0)
    ids_ = check.numbers(traj_ids, "traj_ids", min_size=0, minimum=0)
    if not np.all(ids_ == np.round(ids_)):
        raise ConfigError("traj_ids must hold integer orbit ids")
    if check.numbers(d0, "d0", positive=True).size not in (1, ids_.size):
        raise ConfigError(f"d0 must be one separation or one per orbit of traj_ids ({np.size(d0)} vs {ids_.size})")
    t_from = check.number(t_from, "t_from")
    g_max = check.number(g_max, "g_max", positive=True)
    ids = np.asarray(traj_ids, dtype=np.int64)
    d0 = np.broadcast_to(np.asarray(d0, dtype=float), ids.shape)
    out = pd.DataFrame({"traj_id": ids, "d0": d0})
    b = first_crossings(base_sections[cols], t_from).set_index("traj_id")
    s = first_crossings(shadow_sections[cols], t_from).set_index("traj_id")
    both = out["traj_id"].isin(b.index) & out["traj_id"].isin(s.index)
    one = out["traj_id"].isin(b.index) ^ out["traj_id"].isin(s.index)
    q = ["x", "y", "px", "py"]
    growth = np.full(len(out), np.nan)
    t = np.full(len(out), np.nan)
    if both.any():
        k = out.loc[both, "traj_id"].to_numpy()
        dist = np.linalg.norm(b.loc[k, q].to_numpy() - s.loc[k, q].to_numpy(), axis=1)
        growth[both.to_numpy()] = dist / d0[both.to_numpy()]
        t[both.to_numpy()] = b.loc[k, "t"].to_numpy()
    inb = out["traj_id"].isin(b.index).to_numpy() & ~both.to_numpy()
    t[inb] = b.loc[out.loc[inb, "traj_id"].to_numpy(), "t"].to_numpy()
    growth[one.to_numpy()] = np.inf
    kind = np.where(both & (growth < g_max), "regular", np.where(both | one, "chaotic", "none"))
    with np.errstate(divide="ignore", invalid="ignore"):
        ftle = np.log(growth) / t
    return out.assign(t=t, growth=growth, ftle=ftle, kind=kind, regular=kind == "regular")


def regular_fraction(n_orbits: int, n_regular: int) -> tuple[float, float]:
    """regular_fraction(n_orbits, n_regular) -> (fraction, binomial error √(f(1 − f)/N), at least 1/N's Wilson
    bound near 0 and 1 so a count of 0 has a nonzero error).

    >>> regular_fraction(10000, 0)[1] > 0
    True
    """
    n_orbits = check.count(n_orbits, "n_orbits", 1)
    n_regular = check.count(n_regular, "n_regular", 0)
    if n_regular > n_orbits:
        raise ConfigError(f"n_regular must be ≤ n_orbits = {n_orbits}, got {n_regular}")
    f = n_regular / n_orbits
    z = 1.0
    wilson = z * np.sqrt(f * (1 - f) / n_orbits + z**2 / (4 * n_orbits**2)) / (1 + z**2 / n_orbits)
    return float(f), float(max(np.sqrt(f * (1 - f) / n_orbits), wilson))


#: variational FTLE (1/time) below which an orbit is labelled regular, above which chaotic (undecided between): at
#: T = 3000 a stretch below e⁹ ≈ 8·10³ (a torus' shear) and above e¹⁵ ≈ 3·10⁶
FTLE_REGULAR, FTLE_CHAOTIC = 0.003, 0.005
VARIATIONAL = "variational FTLE"  # the second indicator's name in records


#: the thresholds of the systematic: a decade either side of :data:`G_MAX`
G_MAX_RANGE = (1e3, 1e5)


def threshold_systematic(n_orbits: int, growth, g_max: float = G_MAX, others=G_MAX_RANGE) -> dict:
    """threshold_systematic(n_orbits, growth, g_max=1e4, others=(1e3, 1e5)) -> {value, stat, syst, by_threshold}.

    The regular fraction of ``n_orbits`` orbits (the growth G of each orbit the indicator classified; NaN or
    inf where not regular at any threshold) at the threshold ``g_max`` with its binomial error (``stat``,
    :func:`regular_fraction`), and the systematic of the threshold choice: the largest shift of the fraction when
    the threshold is any of ``others`` (``syst``; ``by_threshold``: {threshold: fraction}). Quoted as
    value ± stat ± syst.

    >>> r = threshold_systematic(1000, [10.0, 50.0, 3e3, 2e4, 1e9, np.inf])
    >>> r["value"], r["by_threshold"], r["syst"]      # 3 below 1e4, 2 below 1e3, 4 below 1e5
    (0.003, {1000.0: 0.002, 10000.0: 0.003, 100000.0: 0.004}, 0.001)
    """
    n_orbits = check.count(n_orbits, "n_orbits", 1)
    _checks.values(growth, "growth", min_size=0)
    g = np.asarray(growth, dtype=float)
    g_max = check.number(g_max, "g_max", positive=True)
    check.numbers(others, "others", positive=True)
    if n_orbits < g.size:
        raise ConfigError(f"n_orbits ({n_orbits}) is smaller than the orbits classified ({g.size})")
    by = {float(x): int(np.sum(g < x)) / n_orbits for x in sorted({float(g_max), *map(float, others)})}
    value, stat = regular_fraction(n_orbits, int(np.sum(g < g_max)))
    return {
        "value": value,
        "stat": stat,
        "syst": float(max(abs(v - value) for v in by.values())),
        "by_threshold": by,
    }


def variational_indicator(
    lifetimes: pd.DataFrame, t_min: float, *, ftle_regular: float = FTLE_REGULAR, ftle_chaotic: float = FTLE_CHAOTIC
) -> pd.DataFrame:
    """variational_indicator(lifetimes, t_min, ftle_regular=0.003, ftle_chaotic=0.005) -> DataFrame per orbit.

    Each orbit's label by its variational finite-time Lyapunov exponent λ_T = Λ/t_end (1/time), Λ the log-stretch
    of its tangent vector at t_end (the engine's tangent dynamics: the lifetimes table of a scene with
    ``tangent = true``). An orbit still inside at t_end ≥ ``t_min`` is 'regular' when λ_T < ``ftle_regular``,
    'chaotic' when λ_T > ``ftle_chaotic``, 'undecided' between; an orbit that escaped (left before t_max) is
    'chaotic' whatever its λ_T (an orbit on a torus never leaves). Columns: traj_id, t_end, ftle, label.

    Parameters
    ----------
    lifetimes : DataFrame
        traj_id, outcome, t_end (time units), log_stretch of a run with the tangent dynamics (conservative).
    t_min : float
        The time (time units) the exponent must span: an orbit censored before ``t_min`` is refused.
    ftle_regular, ftle_chaotic : float
        Thresholds on λ_T (1/time), ``ftle_regular`` ≤ ``ftle_chaotic``.

    Raises
    ------
    ConfigError
        A missing column, an orbit still inside that stopped before ``t_min``, thresholds out of order.

    Examples
    --------
    >>> lt = pd.DataFrame({"traj_id": [0, 1, 2, 3], "t_end": [3000.0, 3000.0, 3000.0, 120.0],
    ...                    "outcome": ["censored", "censored", "censored", "escaped"],
    ...                    "log_stretch": [8.0, 60.0, 12.0, 3.0]})
    >>> variational_indicator(lt, 3000.0)["label"].tolist()
    ['regular', 'chaotic', 'undecided', 'chaotic']
    """
    check.table(lifetimes, "lifetimes", ["traj_id", "outcome", "t_end", "log_stretch"], min_rows=0)
    t_min = check.number(t_min, "t_min", positive=True)
    lo = check.number(ftle_regular, "ftle_regular", positive=True)
    hi = check.number(ftle_chaotic, "ftle_chaotic", positive=True)
    if hi < lo:
        raise ConfigError(f"ftle_chaotic must be ≥ ftle_regular = {lo:g}, got {hi:g}")
    t = lifetimes["t_end"].to_numpy(float)
    lam = lifetimes["log_stretch"].to_numpy(float)
    escaped = (lifetimes["outcome"].astype(str) != "censored").to_numpy()
    short = ~escaped & (t < t_min)
    if short.any():
        raise ConfigError(
            f"lifetimes: {int(short.sum())} orbit(s) still inside stopped before t_min = {t_min:g}: "
            "their exponent does not span the time asked"
        )
    if not np.isfinite(lam[~escaped]).all():
        raise ConfigError("lifetimes: log_stretch must be finite (a run with the tangent dynamics)")
    with np.errstate(divide="ignore", invalid="ignore"):
        ftle = np.where(t > 0, lam / t, np.nan)
    label = np.where(escaped | (ftle > hi), "chaotic", np.where(ftle < lo, "regular", "undecided"))
    return pd.DataFrame({"traj_id": lifetimes["traj_id"].to_numpy(np.int64), "t_end": t, "ftle": ftle, "label": label})


def indicator_systematic(n_orbits: int, n_band: int, shadow_regular, label, in_band) -> dict:
    """indicator_systematic(n_orbits, n_band, shadow_regular, label, in_band) -> the second indicator's systematic.

    The labelled orbits (one entry each: ``shadow_regular`` the shadow indicator's verdict at its threshold,
    ``label`` 'regular', 'chaotic' or 'undecided' by :func:`variational_indicator`, ``in_band`` whether its shadow
    growth lies in the band between tori and the saturated sea) are compared: a decided label that differs from
    the shadow's verdict is a disagreement. Those of the band's labelled orbits are scaled to the whole band
    (``n_band`` orbits of ``n_orbits``: × n_band / n labelled in the band) and give ``syst``, the fraction of all
    orbits that would change class were the band labelled by the second indicator, and ``shift``, the signed
    change of the regular fraction (to regular minus to chaotic). Undecided orbits change nothing and are counted.
    The labelled orbits outside the band (a sample either side) check that the indicators agree there
    (``disagree_outside``).

    Returns {n_labelled, n_band_labelled, n_undecided, disagree_to_regular, disagree_to_chaotic,
    disagree_outside, scale, shift, syst} (counts of the labelled orbits; shift and syst fractions of ``n_orbits``).

    >>> r = indicator_systematic(1000, 200, [True, True, True, False, False, True],
    ...                          ["regular", "chaotic", "undecided", "regular", "chaotic", "chaotic"],
    ...                          [True, True, True, True, True, False])
    >>> r["scale"], r["syst"], r["shift"]      # 5 of 200 labelled: ×40; 2 flips → 80 orbits of 1000
    (40.0, 0.08, 0.0)
    """
    n_orbits = check.count(n_orbits, "n_orbits", 1)
    n_band = check.count(n_band, "n_band", 0)
    if n_band > n_orbits:
        raise ConfigError(f"n_band must be ≤ n_orbits = {n_orbits}, got {n_band}")
    reg = np.asarray(shadow_regular)
    lab = np.asarray(label, dtype=object)
    band = np.asarray(in_band)
    if reg.dtype != bool or band.dtype != bool:
        raise ConfigError("shadow_regular and in_band must be booleans, one per labelled orbit")
    if not (reg.shape == lab.shape == band.shape) or reg.ndim != 1:
        raise ConfigError(
            f"shadow_regular, label and in_band must have one entry per labelled orbit, got "
            f"{reg.shape}, {lab.shape}, {band.shape}"
        )
    bad = set(lab.tolist()) - {"regular", "chaotic", "undecided"}
    if bad:
        raise ConfigError(f"label must hold 'regular', 'chaotic' or 'undecided', got {sorted(map(str, bad))}")
    n_band_lab = int(band.sum())
    if n_band_lab > n_band:
        raise ConfigError(f"in_band marks {n_band_lab} labelled orbits, more than n_band = {n_band}")
    to_reg = ~reg & (lab == "regular")
    to_cha = reg & (lab == "chaotic")
    scale = n_band / n_band_lab if n_band_lab else 0.0
    up, down = int((to_reg & band).sum()), int((to_cha & band).sum())
    return {
        "n_labelled": int(lab.size),
        "n_band_labelled": n_band_lab,
        "n_undecided": int((lab == "undecided").sum()),
        "disagree_to_regular": up,
        "disagree_to_chaotic": down,
        "disagree_outside": int(((to_reg | to_cha) & ~band).sum()),
        "scale": float(scale),
        "shift": float(scale * (up - down) / n_orbits),
        "syst": float(scale * (up + down) / n_orbits),
    }
