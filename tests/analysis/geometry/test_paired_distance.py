"""paired_hellinger_difference: coverage on synthetic sets with a known answer, units (orbits) resampled.

The known answer: point sets drawn from mixtures of uniform densities on rectangles, whose cell
probabilities on every (shifted) box partition are exact (products of interval overlaps), so the true
offset-averaged Hellinger distances and their difference Δ are closed-form. Points come in units (orbits) of
1–3 points that share their mixture component, as crossings of one orbit share its history; B is the set of
the marked units of A (as Fig. 5b is a subset of the orbits of 5a).
"""

import numpy as np
import pytest

from hhscatter.analysis.geometry.paired_distance import (
    UnitSet,
    _offset_extents,
    paired_hellinger_difference,
    paired_hellinger_replicates,
    percentile_interval,
)

EXTENT = (0.0, 1.0, 0.0, 1.0)
WIDE, CORNER = (0.0, 1.0, 0.0, 1.0), (0.0, 0.5, 0.0, 0.5)
W_CORNER = 0.3  # share of A's units in the corner component


def cell_probs(mix, box, ext):
    """Exact box probabilities of a mixture [(weight, (a1, a2, b1, b2))] of uniform rectangles."""
    x0, x1, y0, y1 = ext
    nx, ny = int(np.floor((x1 - x0) / box)) + 1, int(np.floor((y1 - y0) / box)) + 1
    xe, ye = x0 + box * np.arange(nx + 1), y0 + box * np.arange(ny + 1)
    p = np.zeros((nx, ny))
    for w, (a1, a2, b1, b2) in mix:
        ox = np.clip(np.minimum(xe[1:], a2) - np.maximum(xe[:-1], a1), 0, None) / (a2 - a1)
        oy = np.clip(np.minimum(ye[1:], b2) - np.maximum(ye[:-1], b1), 0, None) / (b2 - b1)
        p += w * np.outer(ox, oy)
    return p.ravel()


def true_distances(mark, box, offsets):
    """(d_A, d_B, Δ): offset-averaged Hellinger of A's and B's densities to the uniform reference."""
    a = [(1 - W_CORNER, WIDE), (W_CORNER, CORNER)]
    wb = np.array([(1 - W_CORNER) * mark[0], W_CORNER * mark[1]])
    b = [(wb[0] / wb.sum(), WIDE), (wb[1] / wb.sum(), CORNER)]
    exts = _offset_extents(EXTENT, box, offsets)

    def d(mix):
        h2 = [
            0.5 * np.sum((np.sqrt(cell_probs(mix, box, e)) - np.sqrt(cell_probs([(1.0, WIDE)], box, e))) ** 2)
            for e in exts
        ]
        return float(np.sqrt(np.mean(h2)))

    return d(a), d(b), d(b) - d(a)


def draw(rng, mark, n_units=1000, n_ref=2000, copies=None):
    comp = (rng.random(n_units) < W_CORNER).astype(int)
    k = rng.integers(1, 4, n_units) if copies is None else np.full(n_units, copies)
    units = np.repeat(np.arange(n_units), k)
    pts = rng.random((units.size, 2))
    pts[np.repeat(comp, k) == 1] *= 0.5
    inb = (rng.random(n_units) < np.where(comp == 0, mark[0], mark[1]))[units]
    return pts, units, pts[inb], units[inb], rng.random((n_ref, 2)), np.arange(n_ref)


def coverage(mark, n_exp, seed, box=0.25, offsets=2, n_boot=100):
    truth = true_distances(mark, box, offsets)[2]
    rng = np.random.default_rng(seed)
    hits, est = 0, []
    for e in range(n_exp):
        A, ua, B, ub, R, ur = draw(rng, mark)
        r = paired_hellinger_difference(
            A, B, R, box, EXTENT, units_a=ua, units_b=ub, units_r=ur, offsets=offsets, n_boot=n_boot, seed=e
        )
        hits += r.lo <= truth <= r.hi
        est.append(r.delta)
    return hits / n_exp, truth, np.array(est)


def test_closed_form_reference_is_right():
    """The exact cell probabilities sum to one, and a set equal to the reference is at distance 0."""
    for e in _offset_extents(EXTENT, 0.25, 2):
        assert cell_probs([(0.7, WIDE), (0.3, CORNER)], 0.25, e).sum() == pytest.approx(1.0, abs=1e-12)
    d_a, d_b, delta = true_distances((1.0, 0.0), 0.25, 2)  # B = the wide component only = the reference
    assert d_b == pytest.approx(0.0, abs=1e-12) and delta == pytest.approx(-d_a)


@pytest.mark.parametrize("mark, seed", [((0.5, 0.1), 11), ((0.5, 0.5), 12)])
def test_paired_interval_covers_the_true_difference(mark, seed):
    """95 % intervals on 25 synthetic data sets: B closer than A (Δ = −0.112), and B a random subset (Δ = 0)."""
    cov, truth, est = coverage(mark, 25, seed)
    assert cov >= 0.8, (cov, truth)  # 0.95 expected; ≤ 19 of 25 has p < 0.01
    assert abs(est.mean() - truth) < 3 * est.std(ddof=1) / np.sqrt(est.size) + 0.01


@pytest.mark.slow
@pytest.mark.parametrize("mark, seed", [((0.5, 0.1), 21), ((0.5, 0.5), 22)])
def test_paired_interval_coverage_200_data_sets(mark, seed):
    """Measured: 0.95 (B closer) and 0.95 (null, n_boot = 100); with n_boot = 40 the null case gave 0.91."""
    cov, truth, _ = coverage(mark, 200, seed)
    assert 0.91 <= cov <= 0.99, (cov, truth)


def test_the_unit_is_resampled_not_the_point():
    """Copying every point of every unit three times adds no information, and the result does not move
    (resampling points instead of units would shrink the interval by about √3)."""
    A, ua, B, ub, R, ur = draw(np.random.default_rng(5), (0.5, 0.1))
    kw = dict(box=0.25, extent=EXTENT, n_boot=60, seed=3)
    one = paired_hellinger_difference(A, B, R, units_a=ua, units_b=ub, units_r=ur, **kw)
    three = paired_hellinger_difference(
        np.repeat(A, 3, axis=0),
        np.repeat(B, 3, axis=0),
        np.repeat(R, 3, axis=0),
        units_a=np.repeat(ua, 3),
        units_b=np.repeat(ub, 3),
        units_r=np.repeat(ur, 3),
        **kw,
    )
    assert three.lo == pytest.approx(one.lo, abs=1e-12) and three.hi == pytest.approx(one.hi, abs=1e-12)
    assert three.delta == pytest.approx(one.delta, abs=1e-12)


def test_bad_input_is_refused():
    P = np.random.default_rng(0).random((10, 2))
    ids = np.arange(10)
    with pytest.raises(ValueError, match="one entry per point"):
        paired_hellinger_difference(P, P, P, 0.5, EXTENT, units_a=ids[:5], units_b=ids, units_r=ids)
    with pytest.raises(ValueError, match="n_boot"):
        paired_hellinger_difference(P, P, P, 0.5, EXTENT, units_a=ids, units_b=ids, units_r=ids, n_boot=1)


# ---------------------------------------------------------------------------
# paired_hellinger_replicates: one set against two references (5a against μ_c^0.30 and μ_c^0.35), several runs
# against one reference (5a at several γ, panel (d)); each set its own group, resampled independently
# ---------------------------------------------------------------------------
def mixture(w_corner):
    return [(1 - w_corner, WIDE), (w_corner, CORNER)]


def true_distance(mix_x, mix_r, box, offsets):
    """Offset-averaged Hellinger distance of two mixtures' exact cell probabilities (closed form)."""
    h2 = [
        0.5 * np.sum((np.sqrt(cell_probs(mix_x, box, e)) - np.sqrt(cell_probs(mix_r, box, e))) ** 2)
        for e in _offset_extents(EXTENT, box, offsets)
    ]
    return float(np.sqrt(np.mean(h2)))


def draw_units(rng, w_corner, n_units):
    """Points of n_units units (orbits) of 1–3 points each, every unit in one mixture component; its ids."""
    comp = rng.random(n_units) < w_corner
    k = rng.integers(1, 4, n_units)
    pts = rng.random((k.sum(), 2))
    pts[np.repeat(comp, k)] *= 0.5
    return pts, np.repeat(np.arange(n_units), k)


def multi_coverage(weights, pairs, diff, n_exp, seed, box=0.25, offsets=2, n_boot=100, n_units=1000):
    """Coverage of the paired interval of reps[:, diff[1]] − reps[:, diff[0]] for sets drawn from mixtures
    ``weights`` {name: corner weight}, each set its own run (group)."""
    truth_d = [true_distance(mixture(weights[x]), mixture(weights[r]), box, offsets) for x, r in pairs]
    truth = truth_d[diff[1]] - truth_d[diff[0]]
    rng = np.random.default_rng(seed)
    hits, est = 0, []
    for e in range(n_exp):
        sets = {n: UnitSet(*draw_units(rng, w, n_units), n) for n, w in weights.items()}
        reps = paired_hellinger_replicates(sets, pairs, [box], EXTENT, offsets=offsets, n_boot=n_boot, seed=e)
        d, lo, hi = percentile_interval(reps[:, diff[1], 0] - reps[:, diff[0], 0], 0.95)
        hits += lo <= truth <= hi
        est.append(d)
    return hits / n_exp, truth, np.array(est)


CASES = {
    # one set A (30 % in the corner) against two references: uniform (R1) and 45 % in the corner (R2)
    "two references": ({"A": 0.3, "R1": 0.0, "R2": 0.45}, [("A", "R1"), ("A", "R2")], (0, 1)),
    "two references, null": ({"A": 0.3, "R1": 0.0, "R2": 0.0}, [("A", "R1"), ("A", "R2")], (0, 1)),
    # two runs (30 % and 15 % in the corner) against one uniform reference
    "two runs": ({"A1": 0.3, "A2": 0.15, "R": 0.0}, [("A1", "R"), ("A2", "R")], (0, 1)),
}


def test_closed_form_of_the_multi_cases():
    """The closed forms the coverage tests use: d(A, A) = 0, the null case has Δ = 0, and the cases differ."""
    d = lambda wx, wr: true_distance(mixture(wx), mixture(wr), 0.25, 2)
    assert d(0.3, 0.3) == pytest.approx(0.0, abs=1e-12)
    assert d(0.3, 0.45) - d(0.3, 0.0) == pytest.approx(-0.080, abs=0.001)  # A is closer to R2
    assert d(0.15, 0.0) - d(0.3, 0.0) == pytest.approx(-0.075, abs=0.001)  # A2 is closer to R
    assert d(0.3, 0.0) == pytest.approx(true_distances((1.0, 1.0), 0.25, 2)[0], abs=1e-12)


@pytest.mark.parametrize("case, seed", [("two references", 31), ("two references, null", 32), ("two runs", 33)])
def test_multi_set_paired_interval_covers_the_true_difference(case, seed):
    """95 % intervals of paired differences on 20 synthetic data sets with closed-form distances."""
    weights, pairs, diff = CASES[case]
    cov, truth, est = multi_coverage(weights, pairs, diff, 20, seed)
    assert cov >= 0.8, (cov, truth)  # 0.95 expected; ≤ 15 of 20 has p < 0.003
    assert abs(est.mean() - truth) < 3 * est.std(ddof=1) / np.sqrt(est.size) + 0.01


@pytest.mark.slow
@pytest.mark.parametrize("case, seed", [("two references", 41), ("two references, null", 42), ("two runs", 43)])
def test_multi_set_paired_interval_coverage_200_data_sets(case, seed):
    """Measured: 0.915 (two references), 0.94 (two references, null), 0.925 (two runs); binomial sd 0.015."""
    weights, pairs, diff = CASES[case]
    cov, truth, _ = multi_coverage(weights, pairs, diff, 200, seed)
    assert 0.91 <= cov <= 0.99, (cov, truth)


def test_replicates_pair_the_shared_set_and_reproduce_the_two_set_difference():
    """paired_hellinger_difference is the replicates of (A, R), (B, R) with A, B in one group; a set used in
    two pairs is one half-sample in both (d(R, R) = 0 in every replicate)."""
    A, ua, B, ub, R, ur = draw(np.random.default_rng(7), (0.5, 0.1))
    r = paired_hellinger_difference(A, B, R, 0.25, EXTENT, units_a=ua, units_b=ub, units_r=ur, n_boot=30, seed=2)
    sets = {"A": UnitSet(A, ua, "run"), "B": UnitSet(B, ub, "run"), "R": UnitSet(R, ur, "ref")}
    reps = paired_hellinger_replicates(
        sets, [("A", "R"), ("B", "R"), ("R", "R")], [0.25, 0.5], EXTENT, n_boot=30, seed=2
    )
    assert reps.shape == (30, 3, 2)
    assert r.delta == pytest.approx((reps[:, 1, 0] - reps[:, 0, 0]).mean(), abs=1e-12)
    assert np.all(reps[:, 2] == 0.0)


def test_replicates_refuse_bad_input():
    P, ids = np.random.default_rng(0).random((10, 2)), np.arange(10)
    with pytest.raises(ValueError, match=r"sets\['A'\]: the units must have one entry per point"):
        paired_hellinger_replicates({"A": (P, ids[:5], "a")}, [("A", "A")], [0.5], EXTENT)
    with pytest.raises(ValueError, match="unknown: \\['R'\\]"):
        paired_hellinger_replicates({"A": (P, ids, "a")}, [("A", "R")], [0.5], EXTENT)
    with pytest.raises(ValueError, match="at least 4 units"):
        paired_hellinger_replicates({"A": (P[:3], ids[:3], "a")}, [("A", "A")], [0.5], EXTENT)
