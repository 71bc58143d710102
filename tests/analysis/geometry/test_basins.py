"""Tests of the basin-map measures (hhscatter.analysis.geometry.basins, .uncertainty) on synthetic maps with known answers.

Every random input is seeded.  Known answers: closed forms (straight
boundaries), constructions whose exponent or Wada property is derived in the
test's docstring (middle-thirds Cantor boundaries, Newton's method for
z³ = 1), and generating parameters (Bernoulli outcomes with p = c ε^α).
"""

import itertools
import math

import numpy as np
import pytest

from hhscatter.analysis.geometry import basins, uncertainty
from hhscatter.analysis.stats.intervals import wilson_interval

LN2, LN3 = math.log(2.0), math.log(3.0)
CANTOR_ALPHA = 1.0 - LN2 / LN3  # 1 − D0, D0 = log 2 / log 3 the box dimension of the Cantor set


def h2(p):
    """Binary entropy in nats."""
    return -(p * math.log(p) + (1 - p) * math.log(1 - p))


def within_binomial(hits, n, p_true, z=3.0):
    """True if the observed rate hits/n is consistent with p_true (Wilson interval at ±z)."""
    _, lo, hi = wilson_interval(hits, n, z)
    return lo <= p_true <= hi


# ---------------------------------------------------------------------------
# synthetic maps
# ---------------------------------------------------------------------------
def cantor_level(x, depth):
    """Level n of the middle-thirds gap that holds x (first ternary digit 1 at position n).

    x outside [0, 1] → 0 (the outside counts as the gap of level 0); no digit 1
    among the first ``depth`` digits → depth + 1.
    """
    y = np.where((x < 0) | (x > 1), np.nan, np.asarray(x, dtype=float))
    lev = np.full(y.shape, depth + 1, dtype=np.int64)
    lev[np.isnan(y)] = 0
    for n in range(1, depth + 1):
        y = 3.0 * y
        d = np.floor(y)
        y = y - d
        lev[(d == 1) & (lev == depth + 1)] = n
    return lev


def cantor_stripes(n_cols, n_rows, mod):
    """2-D map constant along rows: label = level of the Cantor gap at the cell centre, mod ``mod``."""
    x = (np.arange(n_cols) + 0.5) / n_cols
    return np.tile(cantor_level(x, 40) % mod, (n_rows, 1))


def newton_basins(n, iterations=40):
    """Basins of the three roots of z³ = 1 under Newton's method on [−1.5, 1.5]², labels 0/1/2."""
    y, x = np.mgrid[-1.5 : 1.5 : n * 1j, -1.5 : 1.5 : n * 1j]
    z = x + 1j * y
    with np.errstate(all="ignore"):
        for _ in range(iterations):
            z = z - (z**3 - 1) / (3 * z**2)
    roots = np.exp(2j * np.pi * np.arange(3) / 3)
    lab = np.argmin(np.abs(z[..., None] - roots), axis=-1)
    lab[~np.isfinite(z)] = -1
    return lab


def three_sectors(n):
    """Three 120° sectors meeting at the centre of an n × n map: a boundary made of three rays."""
    y, x = np.mgrid[-1 : 1 : n * 1j, -1 : 1 : n * 1j]
    a = np.mod(np.arctan2(y, x), 2 * np.pi)
    return np.minimum((a // (2 * np.pi / 3)).astype(int), 2)


# ---------------------------------------------------------------------------
# basin fractions
# ---------------------------------------------------------------------------
def test_fractions_count_valid_cells_and_use_wilson():
    lab = np.zeros((20, 30), dtype=int)
    lab[:, 10:] = 1
    lab[:5, 25:] = 2  # 25 cells
    lab[15:, :] = -1  # 150 cells outside
    r = basins.basin_fractions(lab)
    assert r.basins.tolist() == [0, 1, 2]
    assert r.counts.tolist() == [150, 275, 25] and r.n == 450 and r.n_outside == 150
    p, lo, hi = wilson_interval(np.array([150, 275, 25]), 450, 1.0)
    np.testing.assert_allclose(r.frac, [1 / 3, 275 / 450, 25 / 450])
    np.testing.assert_allclose(r.lo, lo)
    np.testing.assert_allclose(r.hi, hi)
    # a requested basin that is absent gets count 0 and a Wilson interval starting at 0
    r = basins.basin_fractions(lab, basins=[2, 0, 3], z=2.0)
    assert r.counts.tolist() == [25, 150, 0] and r.lo[2] == 0.0 and r.hi[2] > 0.0


def test_fraction_intervals_cover_the_truth_68_percent_of_the_time():
    """Over 400 iid maps (cells drawn with p = 0.2, 0.3, 0.5), the ±1σ Wilson intervals cover p ≈ 68.3 %."""
    rng = np.random.default_rng(1)
    p_true = np.array([0.2, 0.3, 0.5])
    R = 400
    hits = np.zeros(3, dtype=int)
    for _ in range(R):
        lab = rng.choice(3, size=(30, 30), p=p_true)
        r = basins.basin_fractions(lab, basins=[0, 1, 2])
        hits += (r.lo <= p_true) & (p_true <= r.hi)
    for h in hits:
        assert within_binomial(h, R, 0.6827), hits / R


# ---------------------------------------------------------------------------
# basin entropy
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("box", [4, 5, 8])
def test_entropy_of_a_vertical_boundary_matches_the_closed_form(box):
    """Two basins split by a vertical line on an L × L map, L = M·box (M boxes a side, N = M² boxes).

    If the line cuts a column of boxes k cells from their left edge (0 < k < box),
    the M boxes of that column hold the fractions k/box and 1 − k/box, every
    other box one label: S_bb = h(k/box), S_b = M·h(k/box)/M² = h(k/box)/M, N_b = M
    (h the binary entropy).  Mid-box (k = box/2): S_bb = ln 2 exactly, which
    the log 2 criterion (strict >) does not call fractal.  A line on a box
    edge cuts no box: S_b = 0, N_b = 0, S_bb undefined.
    """
    M = 12
    L = M * box
    for k in range(1, box):
        lab = np.zeros((L, L), dtype=int)
        lab[:, 5 * box + k :] = 1
        r = basins.basin_entropy(lab, box)
        assert r.n_boxes == M * M and r.n_boundary == M and r.n_basins == 2
        assert r.S_bb == pytest.approx(h2(k / box), rel=1e-12)
        assert r.S_b == pytest.approx(h2(k / box) / M, rel=1e-12)
        assert r.S_bb_err == pytest.approx(0.0, abs=1e-12)  # every boundary box has the same entropy
        assert not r.log2_fractal
    lab = np.zeros((L, L), dtype=int)
    lab[:, 5 * box + box // 2 :] = 1
    if box % 2 == 0:
        assert basins.basin_entropy(lab, box).S_bb == pytest.approx(LN2, rel=1e-12)
    lab = np.zeros((L, L), dtype=int)
    lab[:, 5 * box :] = 1
    r = basins.basin_entropy(lab, box)
    assert r.S_b == 0.0 and r.n_boundary == 0 and math.isnan(r.S_bb) and not r.log2_fractal


def test_entropy_of_a_diagonal_boundary_matches_the_closed_form():
    """Label 1 above the diagonal (column > row), 0 on and below it, on an L × L map.

    Only the M boxes on the diagonal are cut; each holds box(box − 1)/2 cells of
    label 1 out of box²: S_bb = h((box − 1)/(2 box)), S_b = S_bb/M.
    """
    box, M = 6, 20
    L = box * M
    i, j = np.indices((L, L))
    lab = (j > i).astype(int)
    r = basins.basin_entropy(lab, box)
    q = (box - 1) / (2 * box)
    assert r.n_boundary == M
    assert r.S_bb == pytest.approx(h2(q), rel=1e-12)
    assert r.S_b == pytest.approx(h2(q) / M, rel=1e-12)


def test_entropy_ignores_cells_outside_the_allowed_region():
    """A vertical mid-box boundary with the lower half of the map outside: only the valid boxes count.

    With min_valid = 1 a box that straddles the outside edge is dropped; with
    min_valid = 0.5 it enters, and its frequencies use its valid cells only.
    """
    box, M = 4, 10
    L = box * M
    lab = np.zeros((L, L), dtype=int)
    lab[:, 3 * box + 2 :] = 1
    lab[L // 2 + 2 :, :] = -1  # rows from 22 on: the box row 5 (rows 20–23) is half outside
    r = basins.basin_entropy(lab, box)
    assert r.n_boxes == 5 * M and r.n_boundary == 5
    assert r.S_bb == pytest.approx(LN2) and r.S_b == pytest.approx(5 * LN2 / (5 * M))
    r = basins.basin_entropy(lab, box, min_valid=0.5)
    assert r.n_boxes == 6 * M and r.n_boundary == 6 and r.S_bb == pytest.approx(LN2)
    # a different outside label
    lab2 = np.where(lab == -1, 9, lab)
    assert basins.basin_entropy(lab2, box, outside=9).n_boxes == 5 * M
    # every box of side 8 reaches the outside: basin_entropy refuses, the table gives a row of NaN
    lab[::6, ::6] = -1
    with pytest.raises(ValueError, match="labels: no box"):
        basins.basin_entropy(lab, 8)
    t = basins.basin_entropy_table(lab, boxes=(8,))
    assert t["n_boxes"].tolist() == [0] and np.isnan(t["S_b"][0])


def _expected_box_entropy(n, k):
    """E[S] and P(S > 0) for a box of n cells drawn iid uniformly among k labels (exact multinomial sum)."""
    ES, P0 = 0.0, 0.0
    for c in itertools.product(range(n + 1), repeat=k - 1):
        last = n - sum(c)
        if last < 0:
            continue
        cnt = (*c, last)
        logp = math.lgamma(n + 1) - sum(math.lgamma(v + 1) for v in cnt) - n * math.log(k)
        S = -sum(v / n * math.log(v / n) for v in cnt if v > 0)
        ES += math.exp(logp) * S
        if max(cnt) == n:
            P0 += math.exp(logp)
    return ES, 1.0 - P0


def test_entropy_of_iid_maps_and_its_error():
    """Random maps of 3 labels, iid uniform per cell (the extreme of an intermingled boundary).

    Known answer: S_b = E[S] of a multinomial box of box² cells, S_bb = E[S]/P(S > 0),
    both from the exact multinomial sum, above ln 2: the log 2 criterion fires.
    The error of S_b (sd of S_i/√N, boxes independent here) must match the
    spread of S_b over 60 independent maps.
    """
    box, side = 4, 120
    ES, Pb = _expected_box_entropy(box * box, 3)
    rng = np.random.default_rng(7)
    vals, errs = [], []
    for _ in range(60):
        r = basins.basin_entropy(rng.integers(0, 3, size=(side, side)), box)
        vals.append(r.S_b)
        errs.append(r.S_b_err)
    r0 = basins.basin_entropy(rng.integers(0, 3, size=(side, side)), box)
    assert abs(r0.S_b - ES) < 3 * r0.S_b_err
    assert abs(r0.S_bb - ES / Pb) < 3 * r0.S_bb_err
    assert r0.S_bb > LN2 and r0.log2_fractal and r0.log2_z > 10 and r0.n_basins == 3
    assert abs(np.mean(vals) - ES) < 3 * np.std(vals, ddof=1) / math.sqrt(len(vals))
    ratio = np.std(vals, ddof=1) / np.mean(errs)
    assert 0.72 < ratio < 1.3, ratio


def test_log2_criterion_on_fractal_and_smooth_maps():
    """The log 2 criterion (S_bb > ln 2 ⇒ fractal) on maps whose boundary is known.

    * Newton's method for z³ = 1: the basins share their boundary, the Julia
      set (fractal).  Being only sufficient, the criterion need not fire at
      every box size: on these maps it does with boxes of 3 cells (S_bb above
      ln 2 by > 3σ at 300² and 400²), while at 5–10 cells S_bb ≈ ln 2, the
      larger boxes mostly straddling two basins (measured, not derived).
    * Three 120° sectors: three rays, boundary boxes hold two basins except at
      the centre → S_bb < ln 2, does not fire.
    * Two basins, even intermingled at random: S_i ≤ ln 2 in every box, so the
      criterion can never fire with two basins (it is sufficient, not necessary).
    """
    for n in (300, 400):
        r = basins.basin_entropy(newton_basins(n), 3)
        assert r.log2_fractal and r.log2_z > 3, (n, r)
    for box in (3, 5, 10):
        r = basins.basin_entropy(three_sectors(300), box)
        assert not r.log2_fractal and r.S_bb < LN2, (box, r)
    r = basins.basin_entropy(np.random.default_rng(3).integers(0, 2, size=(100, 100)), 5)
    assert r.S_bb <= LN2 + 1e-12 and not r.log2_fractal


def test_entropy_table_over_box_sizes():
    lab = newton_basins(200)
    t = basins.basin_entropy_table(lab, boxes=(2, 4, 8, 500))
    assert t["box"].tolist() == [2, 4, 8]  # 500 does not fit the map: skipped
    for _, row in t.iterrows():
        r = basins.basin_entropy(lab, int(row["box"]))
        assert row["S_b"] == r.S_b and row["S_bb"] == r.S_bb and row["n_boundary"] == r.n_boundary
    assert np.all(np.diff(t["S_b"]) > 0)  # larger boxes reach more of the boundary


# ---------------------------------------------------------------------------
# uncertainty fraction and exponent
# ---------------------------------------------------------------------------
def test_uncertainty_fraction_counts_changed_outcomes():
    ref = np.array([0, 0, 1, 1, 2, 2, -1, 0])
    one = np.array([0, 1, 1, 1, 2, 0, 0, 0])
    r = uncertainty.uncertainty_fraction(ref, one)
    assert (r.k, r.n, r.n_excluded) == (2, 7, 1) and r.f == pytest.approx(2 / 7)
    # two perturbations each: uncertain if either differs; a perturbed outcome outside excludes the IC
    two = np.stack([one, np.array([0, 0, 2, 1, 2, 2, 0, -1])])
    r = uncertainty.uncertainty_fraction(ref, two)
    assert (r.k, r.n, r.n_excluded) == (3, 6, 2)
    p, lo, hi = wilson_interval(3, 6, 1.0)
    assert (r.f, r.lo, r.hi) == pytest.approx((p, lo, hi))


def test_exact_power_law_is_recovered():
    eps = np.logspace(-8, -2, 7)
    n = 10**12
    f = np.round(0.7 * eps**0.3 * n) / n
    r = uncertainty.uncertainty_exponent(eps, f, n)
    assert r.alpha == pytest.approx(0.3, abs=1e-6) and r.prefactor == pytest.approx(0.7, rel=1e-5)
    assert r.d == pytest.approx(1.7, abs=1e-6) and r.eps_range == (1e-8, 1e-2) and r.n_points == 7


def test_smooth_straight_boundary_has_alpha_one():
    """Uncertainty algorithm on a half-plane classifier: α = 1, d = 2 − α = 1.

    Boundary: the line through (0.5, 0.5) at 0.3 rad to the x axis; outcome =
    side of the line.  An IC is uncertain when one of x ± ε, y ± ε lies on the
    other side, i.e. when its distance to the line is below ε·max(|sin θ|, |cos θ|).
    For ε ≤ 0.1 that strip stays clear of the top and bottom of the unit
    square, so its area — the expected f — is exactly proportional to ε.
    Fresh uniform ICs (2·10^5) for each of 13 ε over 4 decades.
    """
    rng = np.random.default_rng(11)
    th = 0.3
    nx, ny = -math.sin(th), math.cos(th)

    def side(x, y):
        return ((x - 0.5) * nx + (y - 0.5) * ny > 0).astype(int)

    eps = np.logspace(-5, -1, 13)
    N = 200_000
    f = []
    for e in eps:
        x, y = rng.uniform(0, 1, N), rng.uniform(0, 1, N)
        per = np.stack([side(x + e, y), side(x - e, y), side(x, y + e), side(x, y - e)])
        f.append(uncertainty.uncertainty_fraction(side(x, y), per).f)
    r = uncertainty.uncertainty_exponent(eps, f, N)
    assert r.alpha_err < 0.02
    assert abs(r.alpha - 1.0) < 3 * r.alpha_err, r
    assert abs(r.d - 1.0) < 3 * r.d_err
    expected_c = 2 * max(abs(nx), abs(ny)) / math.cos(th)  # strip area per unit ε
    assert abs(math.log(r.prefactor / expected_c)) < 3 * r.prefactor_rel_err
    assert r.p_value > 1e-3


def test_cantor_boundary_has_the_uncertainty_exponent_of_its_dimension():
    """Outcome on [0, 1] = parity of the level of the middle-thirds gap that holds x.

    The boundary is the Cantor set C (every point of C is a limit of gaps of
    both parities; inside a gap the outcome is constant).  At ε = 3^−n the ε-
    neighbourhood of C is covered by the 2^n triadic intervals of level n that
    meet C, and a fixed fraction of each is uncertain (its middle third is a
    gap of level n + 1, the middle of its left third one of level n + 2:
    opposite parities within 3^−n), so f(3^−n) ∝ 2^n 3^−n = ε^(1 − D0) with
    D0 = log 2/log 3: α = 1 − log 2/log 3 ≈ 0.369 and d = 1 − α = D0 (a line of
    ICs, D = 1).  Self-similarity (the left third of the map is the map shrunk
    3 times, parities flipped) gives f(ε) = (2/3) f(3ε) + O(ε), hence
    f = A ε^α − c ε: the local slope is low by ~2^−n, ≈ 0.001 for the fitted
    n = 8 … 15, below σ_α.  ε on the triadic points 3^−n samples the
    log-periodic modulation of A at one phase.  Fresh ICs (3·10^5) per ε,
    perturbations x ± ε.
    """
    rng = np.random.default_rng(2)
    ns = np.arange(8, 16)
    eps = 3.0**-ns
    N, depth = 300_000, int(ns.max()) + 6
    f = []
    for e in eps:
        x = rng.uniform(0, 1, N)
        per = np.stack([cantor_level(x - e, depth) % 2, cantor_level(x + e, depth) % 2])
        f.append(uncertainty.uncertainty_fraction(cantor_level(x, depth) % 2, per).f)
    r = uncertainty.uncertainty_exponent(eps, f, N, dim=1)
    assert r.alpha_err < 0.004
    assert abs(r.alpha - CANTOR_ALPHA) < 3 * r.alpha_err, (r.alpha, r.alpha_err)
    assert abs(r.d - LN2 / LN3) < 3 * r.d_err
    assert abs(r.alpha - 1.0) > 100 * r.alpha_err  # and far from a smooth boundary
    assert r.p_value > 1e-3


def test_uncertainty_exponent_errors_cover_the_truth_68_percent_of_the_time():
    """400 replicates of Bernoulli outcomes with p(ε) = c ε^α (α = 0.4, 13 ε over 4 decades, n = 2·10^4).

    About 68.3 % of the ±1σ intervals of α must contain 0.4 (within the
    binomial error of 400 replicates, ±3σ), and the χ² p-values must look
    uniform (mean 1/2).
    """
    rng = np.random.default_rng(4)
    eps = np.logspace(-6, -2, 13)
    n, alpha = 20_000, 0.4
    p = 0.3 * (eps / 1e-2) ** alpha
    R = 400
    cover, pvals = 0, []
    for _ in range(R):
        r = uncertainty.uncertainty_exponent(eps, rng.binomial(n, p) / n, n)
        cover += abs(r.alpha - alpha) <= r.alpha_err
        pvals.append(r.p_value)
    assert within_binomial(cover, R, 0.6827), cover / R
    assert abs(np.mean(pvals) - 0.5) < 3 * math.sqrt(1 / 12 / R)


def test_eps_range_selects_the_fitted_points():
    rng = np.random.default_rng(9)
    eps = np.logspace(-6, -1, 11)
    n = 50_000
    p = np.minimum(0.2 * (eps / 1e-2) ** 0.5, 0.9)
    p[eps > 2e-2] = 0.9  # saturated: not a power law
    f = rng.binomial(n, p) / n
    r = uncertainty.uncertainty_exponent(eps, f, n, eps_range=(1e-6, 1.5e-2))
    assert r.n_points == 9 and r.eps_range == (pytest.approx(1e-6), pytest.approx(1e-2))
    assert abs(r.alpha - 0.5) < 3 * r.alpha_err
    assert r.fitted.tolist() == [True] * 9 + [False] * 2


# ---------------------------------------------------------------------------
# cut-off of the power law
# ---------------------------------------------------------------------------
EPS13 = np.logspace(-6, -2, 13)


def _broken(eps, alpha, eps_c, beta=1.0, f_top=0.3):
    """p = c ε^α above eps_c, continued with slope beta below (eps_c = 0: a pure power law)."""
    c = f_top / EPS13.max() ** alpha
    if eps_c == 0:
        return c * eps**alpha
    return np.where(eps >= eps_c, c * eps**alpha, c * eps_c**alpha * (eps / eps_c) ** beta)


@pytest.mark.parametrize("beta", [1.0, None])
def test_cutoff_of_a_sharply_broken_power_law_is_found(beta):
    """Bernoulli outcomes with p = c ε^0.4 above ε_c and slope 1 below (a boundary smooth below ε_c).

    ε_c = 10^−3.83 lies midway (in ln ε) between two sampled ε.  The broken
    fit must be preferred (ΔAIC > 0), its ±3σ interval must contain ε_c, α
    within 3σ of 0.4, and with β free, β within 3σ of 1.
    """
    rng = np.random.default_rng(21)
    n = 20_000
    eps_c = 10**-3.83
    f = rng.binomial(n, _broken(EPS13, 0.4, eps_c)) / n
    r = uncertainty.uncertainty_cutoff(EPS13, f, n, beta=beta, z=3.0)
    assert r.detected and r.delta_aic > 10
    assert r.eps_c_lo <= eps_c <= r.eps_c_hi and r.eps_c_hi / r.eps_c_lo < 2.0
    assert r.eps_c_lo < r.eps_c < r.eps_c_hi
    assert abs(r.alpha - 0.4) < 3 * r.alpha_err
    assert r.n_below == 7  # 10^−6 … 10^−4 lie below the break
    if beta is None:
        assert not r.beta_fixed and abs(r.beta - 1.0) < 3 * r.beta_err
    else:
        assert r.beta_fixed and r.beta == 1.0 and r.beta_err == 0.0
    assert r.single.p_value < 1e-6  # the single law fails on these data


def test_cutoff_intervals_cover_the_truth_68_percent_of_the_time():
    """120 replicates of the sharply broken law (ε_c = 10^−4, β = 1 fixed): the ±1σ profile-likelihood
    interval of ε_c and the ±1σ error of α (which includes the uncertainty of
    the break) each cover the truth in ≈ 68.3 % of the replicates (±3σ binomial)."""
    rng = np.random.default_rng(23)
    n, R = 20_000, 120
    p = _broken(EPS13, 0.4, 1e-4)
    cover_c = cover_a = 0
    for _ in range(R):
        r = uncertainty.uncertainty_cutoff(EPS13, rng.binomial(n, p) / n, n, n_grid=60)
        assert r.detected
        cover_c += r.eps_c_lo <= 1e-4 <= r.eps_c_hi
        cover_a += abs(r.alpha - 0.4) <= r.alpha_err
    assert within_binomial(cover_c, R, 0.6827), cover_c / R
    assert within_binomial(cover_a, R, 0.6827), cover_a / R


def test_no_cutoff_gives_an_upper_bound_near_the_smallest_eps():
    """A pure power law (α = 0.4): no cut-off, and ε_c is bounded above close to the smallest ε.

    A break at ε_c > ε_min (slope 1 below, only ε_min below it) lowers
    ln f(ε_min) by s/√k_min with s = (1 − α)√k_min ln(ε_c/ε_min), k_min the
    uncertain ICs at ε_min (σ of ln f ≈ 1/√k).  The 1σ bound is where 2ℓ drops
    by 1 from its maximum: s ≈ 1 for f(ε_min) on the law, s ≈ 1 + |δ| when
    f(ε_min) falls δσ low.  So 0 < s ≤ 5 (allowing δ up to 4).
    """
    rng = np.random.default_rng(22)
    n = 20_000
    p = _broken(EPS13, 0.4, 0.0)
    for _ in range(5):
        k = rng.binomial(n, p)
        r = uncertainty.uncertainty_cutoff(EPS13, k / n, n)
        assert not r.detected and math.isnan(r.eps_c) and r.eps_c_lo == 0.0
        s = 0.6 * math.sqrt(k[0]) * math.log(r.eps_c_hi / EPS13[0])
        assert 0 < s <= 5, s
        assert r.alpha == r.single.alpha


def test_truncated_cantor_boundary_shows_a_cutoff_at_its_finest_scale():
    """The Cantor map of the exponent test, with every gap of level > m = 6 merged into one label.

    Structure finer than the level-m intervals (length 3^−m) is gone: for
    ε ≪ 3^−m the boundary is a finite set of points and f ∝ ε (slope 1), for
    ε ≫ 3^−m f follows the Cantor law ε^0.369.  The detector must find the
    break between the last scale that still holds structure and the first
    that does not: 3^−(m+1) ≤ ε_c ≤ 3^−m (the crossover is not sharp, so
    only this bracket is claimed, not the interval).
    """
    rng = np.random.default_rng(6)
    m = 6
    eps = 3.0 ** -np.arange(3.0, 13.5, 0.5)
    N = 100_000
    f = []
    for e in eps:
        x = rng.uniform(0, 1, N)

        def lab(v):
            return np.minimum(cantor_level(v, 20), m + 1) % 2

        f.append(uncertainty.uncertainty_fraction(lab(x), np.stack([lab(x - e), lab(x + e)])).f)
    r = uncertainty.uncertainty_cutoff(eps, f, N)
    assert r.detected
    assert 3.0 ** -(m + 1) <= r.eps_c <= 3.0**-m, r.eps_c


# ---------------------------------------------------------------------------
# Wada test (merging method)
# ---------------------------------------------------------------------------
def test_wada_cantor_stripes_are_wada_at_three_cells():
    """Label = (level of the Cantor gap at the cell centre) mod 3, as vertical stripes, 3^6 columns.

    Wada by construction: the boundary is C × [0, 1] and every point of C is
    a limit of gaps of every level, hence of all three labels.  On 3^L
    columns the cell centres have ternary digits (column index) then 1, 1, …,
    so next to every gap edge the cells read, going into the neighbouring
    remaining interval, levels L + 1, L, L + 1, L − 1: three consecutive
    levels, all three labels mod 3, within 3 cells.  Hence every boundary cell
    is within 3 cells of the boundary of each basin (W(3) = 1), and not all
    are within 2 (W(2) < 1).
    """
    lab = cantor_stripes(3**6, 40, 3)
    r = basins.wada_merging(lab)
    assert r.wada and r.wada_fraction[3] == 1.0 and r.wada_fraction[2] < 1.0
    assert r.hausdorff.max() == 3.0 and r.r_wada == 3
    assert r.basins.tolist() == [0, 1, 2]
    np.testing.assert_array_less(r.covered[:, 3] - 1e-12, 1.0)
    assert np.all(r.covered[:, 3] == 1.0)


def test_wada_newton_basins_are_wada():
    """Newton's method for z³ = 1: the Julia set is the boundary of every basin of attraction
    (Milnor, Dynamics in One Complex Variable, Cor. 4.12), so the three basins
    share one boundary — Wada.  At 400² cells ≥ 99 % of the boundary cells are
    within 3 cells of every basin's boundary, and the Hausdorff distance does
    not grow with the resolution (slope ≪ 1)."""
    r = basins.wada_merging(newton_basins(400))
    assert r.wada and r.wada_fraction[3] >= 0.99
    assert r.by_resolution["hausdorff"].max() <= 6 and r.hausdorff_slope < 0.5


def test_wada_three_sectors_are_not_wada():
    """Three sectors meeting at one point: away from the centre a boundary ray separates two basins,
    its far end lies ≈ n/2 cells from the third basin.  W(3) is only the
    share of boundary cells near the centre, the Hausdorff distance ≈ n/2
    cells and it grows in proportion to the resolution (slope ≈ 1)."""
    n = 301
    r = basins.wada_merging(three_sectors(n))
    assert not r.wada and r.wada_fraction[3] < 0.05
    assert abs(r.hausdorff.max() - n // 2) <= 2
    assert abs(r.hausdorff_slope - 1.0) < 0.05


def test_wada_two_straight_boundaries_are_not_wada():
    """Three vertical bands of 100 columns: the boundary cells are columns 99, 100 (basins 0|1) and
    199, 200 (1|2); ∂B_2 holds columns 199, 200 and ∂B_0 columns 99, 100, so
    half the boundary cells are 99 cells from the third basin's boundary and
    half 100: W(r) = 0 for r < 99, W(99) = 1/2, W(100) = 1."""
    lab = np.repeat(np.arange(3), 100)[None, :].repeat(120, axis=0)
    r = basins.wada_merging(lab, r_max=120)
    assert not r.wada and r.n_boundary == 4 * 120
    assert np.all(r.wada_fraction[:99] == 0.0) and r.wada_fraction[99] == 0.5 and r.wada_fraction[100] == 1.0
    assert r.hausdorff.tolist() == [100.0, 0.0, 100.0]


def test_wada_basins_selects_labels_and_outside_is_ignored():
    """Cantor stripes with a fourth label painted as a block: testing basins 0, 1, 2 treats it as outside."""
    lab = cantor_stripes(3**6, 40, 3)
    lab[:, :81] = -1
    lab[:10, 200:300] = 7
    r = basins.wada_merging(lab, basins=[0, 1, 2])
    assert r.wada
    assert not basins.wada_merging(lab).wada  # with 7 as a basin: its block edges touch only one other basin


# ---------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------
def test_bad_input_names_the_argument():
    good = np.zeros((10, 10), dtype=int)
    good[:, 5:] = 1
    with pytest.raises(ValueError, match="labels"):
        basins.basin_entropy(np.zeros(10, dtype=int), 2)
    with pytest.raises(ValueError, match="labels"):
        basins.basin_entropy(good + 0.5, 2)
    with pytest.raises(ValueError, match="box"):
        basins.basin_entropy(good, 0)
    with pytest.raises(ValueError, match="box"):
        basins.basin_entropy(good, 11)
    with pytest.raises(ValueError, match="min_valid"):
        basins.basin_entropy(good, 2, min_valid=0.0)
    with pytest.raises(ValueError, match="boxes"):
        basins.basin_entropy_table(good, boxes=(50,))
    with pytest.raises(ValueError, match="labels"):
        basins.basin_fractions(np.full((3, 3), -1))
    with pytest.raises(ValueError, match="basins"):
        basins.basin_fractions(good, basins=[0, 0])
    with pytest.raises(ValueError, match="outcome_perturbed"):
        uncertainty.uncertainty_fraction(np.zeros(5, dtype=int), np.zeros(4, dtype=int))
    with pytest.raises(ValueError, match="outcome_ref"):
        uncertainty.uncertainty_fraction(np.array([0.5, 1.0]), np.array([0, 1]))
    eps, f = np.array([1e-3, 1e-2, 1e-1]), np.array([0.01, 0.05, 0.2])
    with pytest.raises(ValueError, match="eps"):
        uncertainty.uncertainty_exponent(-eps, f, 100)
    with pytest.raises(ValueError, match="eps and f"):
        uncertainty.uncertainty_exponent(eps[:2], f, 100)
    with pytest.raises(ValueError, match="f must"):
        uncertainty.uncertainty_exponent(eps, f + 1, 100)
    with pytest.raises(ValueError, match="n must"):
        uncertainty.uncertainty_exponent(eps, f, 0)
    with pytest.raises(ValueError, match="f·n"):
        uncertainty.uncertainty_exponent(eps, f, 7)
    with pytest.raises(ValueError, match="eps_range"):
        uncertainty.uncertainty_exponent(eps, f, 100, eps_range=(1e-1, 1e-3))
    with pytest.raises(ValueError, match="eps"):
        uncertainty.uncertainty_exponent(eps, f, 100, eps_range=(5e-3, 1.0))  # 2 points left
    with pytest.raises(ValueError, match="f = 1"):
        uncertainty.uncertainty_exponent(eps, np.array([0.01, 0.05, 1.0]), 100)
    with pytest.raises(ValueError, match="dim"):
        uncertainty.uncertainty_exponent(eps, f, 100, dim=0)
    with pytest.raises(ValueError, match="beta"):
        uncertainty.uncertainty_cutoff(eps, f, 100, beta=math.inf)
    with pytest.raises(ValueError, match="min_points"):
        uncertainty.uncertainty_cutoff(eps, f, 100, min_points=0)
    with pytest.raises(ValueError, match="basins"):
        basins.wada_merging(good)  # two basins only
    with pytest.raises(ValueError, match="r_wada"):
        basins.wada_merging(three_sectors(20), r_wada=5, r_max=4)
    with pytest.raises(ValueError, match="steps"):
        basins.wada_merging(three_sectors(20), steps=(2, 4))
    with pytest.raises(ValueError, match="tol"):
        basins.wada_merging(three_sectors(20), tol=1.0)
    with pytest.raises(ValueError, match="labels"):  # three basins kept apart by outside cells: no boundary
        basins.wada_merging(np.tile([0, -1, 1, -1, 2], (5, 1)))


def test_every_kth_cell_holds_the_cells_of_the_coarser_grid():
    """The sub-map read on every k-th cell has the coarser grid's cell centres (x_j = x0 + (j + ½)·Δ_m), so an
    m × m map of the same extent and the sub-map hold the same orbits; grids with even or unit k are left out."""
    n, x0, x1 = 2000, -1.0, 1.0
    centres = x0 + (np.arange(n) + 0.5) * (x1 - x0) / n
    lab = np.broadcast_to(centres, (n, n))  # each cell labelled by its own x
    got = basins.every_kth_cell(lab, [400, 500, 1000, 2000, 333])
    assert [k for k, _ in got] == [5]  # 2000/500 = 4 and 2000/1000 = 2 are even, 2000/2000 = 1, 333 does not divide
    k, sub = got[0]
    want = x0 + (np.arange(400) + 0.5) * (x1 - x0) / 400
    assert sub.shape == (400, 400)
    np.testing.assert_allclose(sub[0], want, rtol=0, atol=1e-12)


def test_zoom_extent_keeps_the_centre_and_divides_the_sides():
    from hhscatter.reproduction.basin_summary import zoom_extent

    x0, x1, y0, y1 = zoom_extent((-1.0, 1.0, -0.5, 0.5), (0.2, -0.1), 4)
    assert (x1 - x0, y1 - y0) == pytest.approx((0.5, 0.25))
    assert ((x0 + x1) / 2, (y0 + y1) / 2) == pytest.approx((0.2, -0.1))


def test_orbit_stretch_is_the_closed_form_of_a_linear_rate_and_the_mean_history_of_predicted_cutoff():
    """Λ = t_end·⟨λ⟩ over ln E: for λ(E) = a + bE, ⟨λ⟩ = a + b(e0 − e_end)/ln(e0/e_end) exactly (the rate is linear
    inside the interpolation's nodes); an orbit with the mean history (ends at E_c after τ2) gives −ln ε_c of
    predicted_cutoff; an orbit that does not lose energy gathers λ(e0)·t_end."""
    from hhscatter.analysis.geometry.cutoff import orbit_stretch, predicted_cutoff

    a, b = 0.1, 1.5
    E = np.linspace(0.1, 0.4, 7)
    e0, e_end, t_end = np.array([0.35, 0.3, 0.25]), np.array([0.15, 0.29, 0.25]), np.array([40.0, 3.0, 7.0])
    got = orbit_stretch(e0, e_end, t_end, E, a + b * E)
    mean = np.where(e0 > e_end, a + b * (e0 - e_end) / np.log(e0 / np.where(e0 > e_end, e_end, 1)), a + b * e0)
    np.testing.assert_allclose(got, t_end * mean, rtol=1e-6)
    for mu, g, E0 in ((0.94, 0.01, 0.3), (0.6, 0.05, 0.25)):
        tau2 = math.log(E0 / 0.15) / (mu * g)
        lam = orbit_stretch([E0], [0.15], [tau2], E, a + b * E)[0]
        assert lam == pytest.approx(-math.log(predicted_cutoff(E0, g, mu, E, a + b * E, 0.15)), rel=1e-6)


def test_stretch_tail_counts_the_orbits_beyond_ln_one_over_eps_exactly_and_covers_the_closed_form():
    """S(ln 1/ε) counts Λ > ln(1/ε) strictly (an orbit at exactly ln(1/ε) does not part the pair); on exponential
    lifetimes on a hyperbolic saddle, Λ = λt with P(t > T) = e^{−κT}, S(ln 1/ε) = ε^{κ/λ} (the uncertainty exponent
    α = κ/λ), and the 1σ Wilson interval covers it in about 68 % of 200 samples."""
    from hhscatter.analysis.geometry.cutoff import stretch_tail

    r = stretch_tail([math.log(10.0), 1.0, 30.0, 2.5], [0.1, 1e-12])
    assert r.k.tolist() == [2, 1] and r.n == 4  # ln(1/0.1) itself is not beyond
    kappa, lam, eps = 0.2, 0.5, np.array([1e-1, 1e-3, 1e-6])
    rng = np.random.default_rng(7)
    hits = 0
    for _ in range(200):
        r = stretch_tail(lam * rng.exponential(1 / kappa, 4000), eps)
        hits += np.count_nonzero((r.lo <= eps ** (kappa / lam)) & (eps ** (kappa / lam) <= r.hi))
    assert 0.60 < hits / (200 * eps.size) < 0.76


def test_stretch_tail_refuses_a_stretch_that_is_not_finite():
    from hhscatter.analysis.geometry.cutoff import stretch_tail
    from hhscatter.errors import ConfigError

    with pytest.raises(ConfigError, match="stretch must be finite for every orbit, got nan at orbit 1"):
        stretch_tail([1.0, float("nan")], [0.1])
