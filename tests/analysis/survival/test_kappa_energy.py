"""hhscatter.analysis.survival.kappa_energy: the steps of fit_kappa_energy on κ(E) points of a known piecewise law."""

import numpy as np
import pytest

from hhscatter.analysis.survival.kappa_energy import (
    _bootstrap_replicates,
    _continuous_covariance,
    _discontinuous_covariance,
    _fit_continuous,
    _kappa_points,
    fit_kappa_energy,
)

E_C = 1.0 / 6.0
A, B, E_B = 13.63, 0.03, 0.27  # the paper's law; continuous: c = a x_b + b
C = A * (E_B - E_C) + B
E = np.linspace(0.18, 0.50, 33)


def law(E, a=A, b=B, c=C, E_b=E_B):
    x = np.asarray(E) - E_C
    return np.where(np.asarray(E) < E_b, a * x**2 + b * x, c * x)


def test_points_are_checked_and_weighted():
    x, _, w, given = _kappa_points(E, law(E), 0.5 * np.ones(E.size), E_C)
    np.testing.assert_array_equal(x, E - E_C)
    np.testing.assert_array_equal(w, np.full(E.size, 4.0))
    assert given
    assert not _kappa_points(E, law(E), None, E_C)[3]
    with pytest.raises(ValueError, match="exceed E_c"):
        _kappa_points(np.r_[E_C, E], np.r_[0.0, law(E)], None, E_C)
    with pytest.raises(ValueError, match="positive"):
        _kappa_points(E, law(E), np.r_[0.0, np.ones(E.size - 1)], E_C)
    with pytest.raises(ValueError, match="differ in length"):
        _kappa_points(E, law(E)[1:], None, E_C)


def test_exact_points_give_the_law_back():
    """Noiseless κ(E) of the continuous law: a, b, c and E_b to 1e-6, χ² ≈ 0, in both models."""
    err = 1e-3 * np.ones(E.size)
    fit = fit_kappa_energy(E, law(E), err, E_C, n_boot=0)
    assert (fit.a, fit.b, fit.c, fit.E_b) == pytest.approx((A, B, C, E_B), rel=1e-6)
    assert fit.chi2 < 1e-8 and fit.dof == E.size - 3 and fit.boot.shape == (0, 4) and fit.boot_err == ()
    # a jump at the break (c ≠ a x_b + b): the separate fits find the law, E_b in the gap of the bracketing points
    jump = law(E, c=1.6)
    disc = fit_kappa_energy(E, jump, err, E_C, continuous=False, n_boot=0)
    assert (disc.a, disc.b, disc.c) == pytest.approx((A, B, 1.6), rel=1e-9)
    below, above = E[E < E_B].max(), E[E >= E_B].min()
    assert disc.E_b == pytest.approx(0.5 * (below + above), rel=1e-12)
    assert disc.E_b_err == pytest.approx((above - below) / np.sqrt(12.0), rel=1e-9)


def test_continuous_covariance_is_the_gauss_newton_inverse():
    """Against a finite-difference Jacobian of κ(x) = b x + a x min(x, x_b), and c = a x_b + b by the delta method."""
    x = E - E_C
    w = np.full(x.size, 1.0 / 0.003**2)
    xb = 0.2745 - E_C  # between two energies: the model is smooth in x_b there
    cov, dof = _continuous_covariance(x, w, A, xb, 0.0, True)

    def model(p):
        a, b, xb_ = p
        return b * x + a * x * np.minimum(x, xb_)

    p, h = np.array([A, B, xb]), np.array([1e-6, 1e-8, 1e-7])
    J = np.column_stack(
        [(model(p + h[i] * np.eye(3)[i]) - model(p - h[i] * np.eye(3)[i])) / (2 * h[i]) for i in range(3)]
    )
    cov3 = np.linalg.inv((J.T * w) @ J)
    g_c = np.array([xb, 1.0, A])  # ∂c/∂(a, b, x_b)
    assert dof == x.size - 3
    np.testing.assert_allclose(np.diag(cov)[[0, 1, 3]], np.diag(cov3), rtol=1e-4)
    assert cov[2, 2] == pytest.approx(g_c @ cov3 @ g_c, rel=1e-4)
    # without given errors the covariance is scaled by χ²/dof
    scaled, _ = _continuous_covariance(x, w, A, xb, 2.0 * dof, False)
    np.testing.assert_allclose(scaled, 2.0 * cov, rtol=1e-12)


def test_discontinuous_covariance_blocks():
    F1, F2 = np.array([[4.0, 1.0], [1.0, 9.0]]), np.array([[0.25]])
    cov, dof = _discontinuous_covariance(F1, F2, 0.01, 30.0, 20, True)
    expected = np.zeros((4, 4))
    expected[:2, :2], expected[2, 2], expected[3, 3] = F1, 0.25, 0.01
    assert dof == 16
    np.testing.assert_array_equal(cov, expected)
    scaled, _ = _discontinuous_covariance(F1, F2, 0.01, 32.0, 20, False)  # χ²/dof = 2 scales the fits, not E_b
    np.testing.assert_array_equal(np.diag(scaled), [8.0, 18.0, 0.5, 0.01])


def test_bootstrap_replicates_are_seeded_resamples():
    rng = np.random.default_rng(2)
    x = E - E_C
    err = 0.01 * law(E) + 2e-4
    y = law(E) + err * rng.standard_normal(E.size)
    w = 1 / err**2
    one = _bootstrap_replicates(x, y, w, True, 400, 30, 7)
    assert one.shape == (30, 4)
    np.testing.assert_array_equal(one, _bootstrap_replicates(x, y, w, True, 400, 30, 7))
    assert not np.array_equal(one, _bootstrap_replicates(x, y, w, True, 400, 30, 8))
    # the first replicate is the refit on the first resample of the seeded generator
    idx = np.random.default_rng(7).integers(0, x.size, x.size)
    np.testing.assert_array_equal(one[0], _fit_continuous(x[idx], y[idx], w[idx], 100)[:4])
    # replicates scatter around the truth (a, b, c, x_b)
    med, sd = np.nanmedian(one, axis=0), np.nanstd(one, axis=0)
    assert np.all(np.abs(med - [A, B, C, E_B - E_C]) < 3 * sd) and np.all(sd > 0)


def test_covariance_errors_cover_the_truth():
    """Over 200 noisy data sets of the known law, the 1σ covariance errors of a, b, c and E_b cover the truth
    ~68 % of the time (binomial sd 3.3 %: 0.55 … 0.80 allows ~4σ; measured 0.685, 0.66, 0.65, 0.70)."""
    rng = np.random.default_rng(11)
    err = 0.01 * law(E) + 2e-4
    hits = {"a": 0, "b": 0, "c": 0, "E_b": 0}
    n = 200
    for _ in range(n):
        fit = fit_kappa_energy(E, law(E) + err * rng.standard_normal(E.size), err, E_C, n_grid=200, n_boot=0)
        for name, true in (("a", A), ("b", B), ("c", C), ("E_b", E_B)):
            hits[name] += abs(getattr(fit, name) - true) <= getattr(fit, name + "_err")
    for name, h in hits.items():
        assert 0.55 <= h / n <= 0.80, (name, h / n)
