"""Transfer operators (hhscatter.analysis.geometry.transfer) on exact cases: open maps with closed-form escape rates and
conditionally invariant densities, the true-time root of a two-state chain, the time-binned propagation of a
renewal process, and the Perron-vector conventions."""

import math

import numpy as np
import pytest
import scipy.sparse as sp

from hhscatter.analysis.geometry import transfer as tf


def _ulam_1d(f, n_boxes, m):
    """Ulam samples of a map f of [0, 1] (image outside [0, 1]: escape), m midpoint samples per box."""
    x = ((np.arange(n_boxes)[:, None] + (np.arange(m)[None, :] + 0.5) / m) / n_boxes).ravel()
    src = np.repeat(np.arange(n_boxes), m)
    y = f(x)
    inside = (y >= 0) & (y < 1)
    dst = np.where(inside, np.floor(np.where(inside, y, 0) * n_boxes).astype(int), -1)
    return tf.Transitions(src, dst, np.ones(x.size), n_boxes)


def _tent(s):
    return lambda x: np.where(x < 0.5, s * x, s * (1 - x))


@pytest.mark.parametrize("s", [2.5, 3.0, 4.4])
def test_open_tent_map_escape_rate_is_ln_half_slope(s):
    # closed form: T^{-1}[0,1] has Lebesgue measure 2/s and Lebesgue is conditionally invariant: κ = ln(s/2)
    # (the sampling error of M = 400 midpoints per box is ~1e-3 relative at these slopes)
    tr = _ulam_1d(_tent(s), 200, 400)
    assert tf.map_escape_rate(tr) == pytest.approx(math.log(s / 2), rel=3e-3)
    lam, v = tf.leading_left(tf.transfer_matrix(tr))
    assert lam == pytest.approx(2 / s, rel=3e-3)
    # the conditionally invariant density is uniform
    assert np.max(np.abs(v * 200 - 1)) < 0.05
    # ARPACK path (n > DENSE_MAX) and LAPACK path agree on a coarse partition
    small = _ulam_1d(_tent(s), 40, 400)
    assert tf.map_escape_rate(small) == pytest.approx(math.log(s / 2), rel=5e-3)


def test_conjugate_open_map_has_the_pulled_back_density():
    # G = h⁻¹ ∘ T ∘ h with h(x) = x² and T the open tent map of slope 3: same escape rate ln(3/2), and the
    # c-density is the uniform one of T pulled back, h'(x) = 2x: box j holds x_{j+1}² − x_j²
    T = _tent(3.0)

    def G(x):
        u = T(x * x)
        return np.where((u >= 0) & (u <= 1), np.sqrt(np.clip(u, 0, None)), 2.0)

    n = 100
    tr = _ulam_1d(G, n, 400)
    lam, v = tf.leading_left(tf.transfer_matrix(tr))
    # Ulam's bias on a non-linear map: below 1 % here (0.75 % measured at n = 100, 0.15 % at n = 200)
    assert -math.log(lam) == pytest.approx(math.log(1.5), rel=1e-2)
    edges = np.linspace(0, 1, n + 1)
    exact = edges[1:] ** 2 - edges[:-1] ** 2
    assert np.max(np.abs(v - exact)) < 0.1 * exact.max()
    assert np.sum(np.abs(v - exact)) < 0.03  # total variation ½Σ|·| < 1.5 %
    # the uniform density is *not* the answer here (the test can fail)
    assert np.sum(np.abs(v - 1.0 / n)) > 0.3


def test_true_time_root_of_a_two_state_chain():
    # A → B with probability p = 0.7 after T1 = 1.5, else escape; B → A with q = 0.5 after T2 = 2.5.
    # ρ(M(κ)) = √(p q e^{κ(T1+T2)}) = 1  ⇒  κ = −ln(pq)/(T1 + T2); the map's rate per return is −ln(pq)/2
    src = np.r_[np.zeros(10, int), np.ones(10, int)]
    dst = np.r_[np.ones(7, int), -np.ones(3, int), np.zeros(5, int), -np.ones(5, int)]
    T = np.r_[np.full(10, 1.5), np.full(10, 2.5)]
    tr = tf.Transitions(src, dst, T, 2)
    assert tf.true_time_kappa(tr) == pytest.approx(-math.log(0.35) / 4.0, rel=1e-10)
    assert tf.map_escape_rate(tr) == pytest.approx(-math.log(0.35) / 2.0, rel=1e-12)
    # weights enter as sample measure: doubling the weight of the escaping samples of A lowers p to 7/13
    w = np.r_[np.ones(7), np.full(3, 2.0), np.ones(10)]
    trw = tf.Transitions(src, dst, T, 2, w)
    assert tf.true_time_kappa(trw) == pytest.approx(-math.log(7 / 13 * 0.5) / 4.0, rel=1e-10)


def test_true_time_root_equals_the_renewal_rate_with_random_times():
    # one state, return with probability q after a time T ~ sample: the root solves (1/M)Σ_ret e^{κT} = 1
    rng = np.random.default_rng(3)
    T = rng.gamma(3.0, 1.0, 500)
    dst = np.where(rng.random(500) < 0.6, 0, -1)
    tr = tf.Transitions(np.zeros(500, int), dst, T, 1)
    k = tf.true_time_kappa(tr)
    assert np.mean(np.where(dst == 0, np.exp(k * T), 0.0)) == pytest.approx(1.0, abs=1e-10)


@pytest.mark.parametrize("n, per_state", [(10, 3), (50, 3), (400, 2)])
def test_communicating_classes_are_the_strongly_connected_components(n, per_state):
    """Random transition graphs with cycles and self-loops (scipy 1.13.0 with numpy 2 never returned on such graphs,
    hence the floor scipy >= 1.13.1): the classes against reachability computed independently (i ~ j iff each
    reaches the other, transitive closure by repeated Boolean squaring)."""
    rng = np.random.default_rng(n)
    m = per_state * n
    src, dst = rng.integers(0, n, m), np.where(rng.random(m) < 0.1, -1, rng.integers(0, n, m))
    labels, classes = tf.communicating_classes(tf.Transitions(src, dst, np.ones(m), n))
    reach = np.eye(n, dtype=bool)
    reach[src[dst >= 0], dst[dst >= 0]] = True
    for _ in range(int(np.ceil(np.log2(n))) + 1):
        reach = reach | ((reach.astype(np.int64) @ reach.astype(np.int64)) > 0)
    same = reach & reach.T
    assert (same == (labels[:, None] == labels[None, :])).all()
    assert sorted(c.label for c in classes) == list(range(labels.max() + 1))


def test_closed_class_has_no_root_and_is_separated():
    # states 0, 1 leak into each other and out; state 2 maps to itself (an 'island'); 3 → 2 (transient)
    src = np.array([0, 0, 0, 1, 1, 2, 2, 3])
    dst = np.array([1, -1, 2, 0, -1, 2, 2, 2])
    tr = tf.Transitions(src, dst, np.ones(8), 4)
    with pytest.raises(ValueError, match="no root"):
        tf.true_time_kappa(tr)
    labels, classes = tf.communicating_classes(tr)
    assert labels[0] == labels[1] != labels[2] != labels[3]
    closed = [c for c in classes if c.closed]
    assert len(closed) == 1 and closed[0].label == labels[2]
    keep, _ = tf.saddle_class(tr)
    assert keep.tolist() == [True, True, False, False]
    # a sample of weight 0 is no transition: with the escape of state 1 weighted 0, {0, 1} still leaks via 0
    w0 = tf.Transitions(src, dst, np.ones(8), 4, np.array([1, 1, 0, 1, 0, 1, 1, 1.0]))
    lab0, cl0 = tf.communicating_classes(w0)
    assert lab0[0] == lab0[1] and [c.closed for c in cl0 if c.label == lab0[0]] == [False]
    sub = tr.subset(keep)  # transitions into the island become leaks of the saddle class
    P = tf.transfer_matrix(sub).toarray()
    assert P.tolist() == [[0.0, 1 / 3], [0.5, 0.0]]
    assert tf.map_escape_rate(sub) == pytest.approx(-0.5 * math.log(1 / 6))


@pytest.mark.parametrize("n", [12, 300])
def test_perron_vector_is_a_positive_probability_vector(n):
    rng = np.random.default_rng(n)
    A = sp.random(n, n, density=0.2, random_state=rng, format="csr") + sp.eye(n) * 0.01
    A = A.tocsr()
    lam, v = tf.leading_left(A)
    assert np.all(v >= 0) and v.sum() == pytest.approx(1.0)
    assert np.allclose(v @ A.toarray(), lam * v, atol=1e-10)
    dense = np.linalg.eigvals(A.toarray())
    assert lam == pytest.approx(np.max(np.abs(dense)), rel=1e-9)
    # the scale and sign of A's eigenvector do not matter: 3A has the same normalised vector
    lam3, v3 = tf.leading_left(3.0 * A)
    assert lam3 == pytest.approx(3 * lam) and np.allclose(v3, v, atol=1e-9)
    with pytest.raises(ValueError, match="non-negative"):
        tf.leading_left(-A)


def test_renewal_survival_and_first_crossing_after_t_star():
    # one state: with q = 0.6 the orbit returns after T = 2.0, else it leaves at t = 1.0. With dt = 0.1:
    # P(t) = q^m on [2m, 2m + 1) and q^{m+1} on [2m + 1, 2m + 2)
    q, dt = 0.6, 0.1
    dst = np.r_[np.zeros(6, int), -np.ones(4, int)]
    tr = tf.Transitions(np.zeros(10, int), dst, np.full(10, 2.0), 1)
    t_end = np.r_[np.full(6, 2.0), np.full(4, 1.0)]
    K, H, L = tf.lag_kernels(tr, t_end, dt)
    assert L == 20
    n = tf.propagate([1.0], K, L, 100)
    P = tf.survival_from_crossings(n, H)
    k = np.arange(101)
    m, rem = k // 20, k % 20
    exact = np.where(rem < 10, q**m, q ** (m + 1))
    assert np.allclose(P, exact, atol=1e-12)
    # first crossing at or after t* = 2.5 (step 25): the crossing at t = 4 of the q² that are still there
    fc = tf.first_crossing_after(n, K, L, 25)
    assert fc[0] == pytest.approx(q * q)
    w = tf.first_crossing_weights(n, tr, dt, 25)
    assert w.sum() == pytest.approx(q * q) and np.all(w[dst < 0] == 0)
    # a lag cap of 15 steps brings the returns forward to t = 1.5: P then drops by q every 1.5 time units
    Kc, Hc, Lc = tf.lag_kernels(tr, t_end, dt, max_lag=15)
    assert Lc == 15 and tf.capped_share(tr, dt, 15) == 1.0 and tf.capped_share(tr, dt, 20) == 0.0
    Pc = tf.survival_from_crossings(tf.propagate([1.0], Kc, Lc, 45), Hc)
    assert Pc[44] == pytest.approx(q**3)


def test_first_crossing_weights_sum_to_the_state_distribution():
    rng = np.random.default_rng(5)
    n_s, m = 6, 400
    src = rng.integers(0, n_s, m)
    dst = np.where(rng.random(m) < 0.8, rng.integers(0, n_s, m), -1)
    T = rng.uniform(0.5, 3.0, m)
    tr = tf.Transitions(src, dst, T, n_s, rng.uniform(0.5, 2.0, m))
    K, H, L = tf.lag_kernels(tr, np.where(dst >= 0, T, rng.uniform(0.1, 2.0, m)), 0.1)
    n = tf.propagate(np.full(n_s, 1.0 / n_s), K, L, 120)
    w = tf.first_crossing_weights(n, tr, 0.1, 77)
    by_dst = np.bincount(dst[dst >= 0], weights=w[dst >= 0], minlength=n_s)
    assert np.allclose(by_dst, tf.first_crossing_after(n, K, L, 77), rtol=1e-12, atol=1e-15)
    # survival by the FFT convolution equals the direct sum Σ_k' n(k')·H(k − k')
    P = tf.survival_from_crossings(n, H)
    direct = [sum(n[kp] @ H[k - kp] for kp in range(k + 1) if k - kp < H.shape[0]) for k in (0, 13, 60, 120)]
    assert np.allclose(P[[0, 13, 60, 120]], direct, atol=1e-12)


def test_flux_density_of_a_radial_potential():
    # V = r²/2: ṗ_r = v²/r − r with v² = 2E − r², density |ṗ_r|/v (independent closed form)
    class Harmonic:
        @staticmethod
        def potential(x, y):
            return 0.5 * (np.asarray(x) ** 2 + np.asarray(y) ** 2)

    E = 0.5
    x = np.array([0.1, 0.3, 0.6, 0.9, 1.2])
    y = np.zeros_like(x)
    r, v2 = x, 2 * E - x * x
    exact = np.where(v2 > 0, np.abs(v2 / np.where(r > 0, r, 1) - r) / np.sqrt(np.clip(v2, 1e-300, None)), 0.0)
    got = tf.section_flux_density(Harmonic, x, y, E)
    assert np.allclose(got, exact, rtol=1e-6)
    assert got[-1] == 0.0  # V ≥ E: not on the section
    # at r² = E the radial acceleration vanishes (circular orbit): the flow is tangent to the section
    assert tf.section_flux_density(Harmonic, math.sqrt(E), 0.0, E) == pytest.approx(0.0, abs=1e-6)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="one entry per sample"):
        tf.Transitions([0, 1], [0], [1.0, 1.0], 2)
    with pytest.raises(ValueError, match="src must lie"):
        tf.Transitions([2], [0], [1.0], 2)
    with pytest.raises(ValueError, match="return times"):
        tf.Transitions([0], [0], [0.0], 1)


def test_saddle_measure_covers_the_downstream_states_and_not_the_island():
    # class {0, 1}: 0 → 0, 1, 2, 3 (1/4 each); 1 → 0 (1/2), else escape; state 2 (downstream) returns to
    # itself with 1/4, else escapes; state 3 is an island (always back to itself). T ≡ 1.
    src = np.array([0, 0, 0, 0, 1, 1, 2, 2, 2, 2, 3])
    dst = np.array([0, 1, 2, 3, 0, -1, 2, -1, -1, -1, 3])
    tr = tf.Transitions(src, dst, np.ones(11), 4)
    keep, _ = tf.saddle_class(tr)
    assert keep.tolist() == [True, True, False, False]
    k = tf.true_time_kappa(tr.subset(keep))
    assert k == pytest.approx(math.log(2.0))  # ρ([[1/4, 1/4], [1/2, 0]]) = 1/2 per step
    nu, lam = tf.saddle_measure(tr, k, keep)
    assert lam == pytest.approx(1.0)
    M = tf.transfer_matrix(tr, k).toarray()
    assert np.allclose((nu @ M)[:3], nu[:3])
    # closed form with e^κ = 2: ν1 = ν0/2 and ν2 = ν0/2 + ν2/2, so ν = (1, 1/2, 1, 0)/(5/2)
    assert np.allclose(nu, [0.4, 0.2, 0.4, 0.0])


def test_bootstrap_error_matches_the_spread_of_independent_estimates():
    # a 12-state open chain with known transition probabilities and return times T ~ 1 + Exp(1); M = 30
    # samples per state. The Poisson bootstrap's std must match the spread of κ over independent sample sets.
    rng = np.random.default_rng(11)
    n, m = 12, 30
    P = rng.random((n, n)) * (rng.random((n, n)) < 0.4)
    P = 0.8 * P / P.sum(axis=1, keepdims=True)  # 20 % escape per return
    cum = np.cumsum(np.c_[P, 1 - P.sum(axis=1)], axis=1)

    def draw(g):
        src = np.repeat(np.arange(n), m)
        u = g.random(src.size)
        j = np.array([np.searchsorted(cum[i], x, side="right") for i, x in zip(src, u)])
        return tf.Transitions(src, np.where(j < n, j, -1), 1.0 + g.exponential(1.0, src.size), n)

    est, boot_sd = [], []
    for r in range(40):
        tr = draw(np.random.default_rng(100 + r))
        est.append(tf.true_time_kappa(tr.subset(tf.saddle_class(tr)[0])))
        if r < 8:
            boot_sd.append(np.std(tf.bootstrap_kappa(tr, 40, rng=r), ddof=1))
    ratio = np.mean(boot_sd) / np.std(est, ddof=1)
    assert 0.7 < ratio < 1.4, ratio


def test_long_cycle_has_its_perron_root_and_vector():
    """Eigenvalues of equal modulus on a circle, ρ·e^{2πik/n}: largest *magnitude* is ambiguous (ARPACK
    stalled with a bare ArpackNoConvergence, or returned a complex root), largest real part converges
    (with the retry on 64 Lanczos vectors). Closed form: a cycle of n = 200 states scaled by 0.9 and
    conjugated by a positive diagonal D has ρ = 0.9 and left Perron vector ∝ diag(D)."""
    n = 200
    C = sp.csr_matrix((np.full(n, 0.9), (np.arange(n), (np.arange(n) + 1) % n)), shape=(n, n))
    d = np.exp(np.random.default_rng(0).normal(size=n))
    A = (sp.diags(1.0 / d) @ C @ sp.diags(d)).tocsr()
    assert A.shape[0] > tf.DENSE_MAX  # the ARPACK path
    assert tf.spectral_radius(A) == pytest.approx(0.9, abs=1e-10)
    lam, v = tf.leading_left(A)
    assert lam == pytest.approx(0.9, abs=1e-10)
    np.testing.assert_allclose(v, d / d.sum(), rtol=1e-8)


def test_arpack_stall_is_a_clear_error_not_a_wrong_root(monkeypatch):
    """If ARPACK stalls twice (a spectrum too close to a circle), the caller gets a ValueError saying so."""

    def stall(*a, **k):
        raise sp.linalg.ArpackNoConvergence("stalled", np.empty(0), np.empty((0, 0)))

    monkeypatch.setattr(tf, "eigs", stall)
    A = sp.random(100, 100, density=0.1, random_state=1, format="csr")
    for f in (tf.spectral_radius, tf.leading_left):
        with pytest.raises(ValueError, match="no Perron root of this 100-state matrix"):
            f(A)


def test_three_block_cycle_matches_lapack():
    """Three blocks visited in turn (the three-exit section's Ulam matrices come close to this): the spectrum
    has the 3-fold symmetry λ → λ·e^{2πi/3}, so three roots share the largest modulus. Independent reference:
    dense LAPACK on the same matrix."""
    import scipy.linalg

    rng = np.random.default_rng(3)
    n, m = 300, 100
    A = np.zeros((n, n))
    for b in range(3):
        c = (b + 1) % 3
        A[b * m : (b + 1) * m, c * m : (c + 1) * m] = rng.random((m, m)) * (rng.random((m, m)) < 0.05)
    vals, left = scipy.linalg.eig(A.T)
    top = np.abs(vals) > np.abs(vals).max() * (1 - 1e-9)
    assert top.sum() == 3  # the ambiguity is really there
    j = int(np.argmax(vals.real))
    ref = np.abs(left[:, j].real) / np.abs(left[:, j].real).sum()
    S = sp.csr_matrix(A)
    assert tf.spectral_radius(S) == pytest.approx(vals[j].real, rel=1e-10)
    lam, v = tf.leading_left(S)
    assert lam == pytest.approx(vals[j].real, rel=1e-10)
    np.testing.assert_allclose(v, ref, rtol=1e-7, atol=1e-12)


@pytest.mark.parametrize("n", [2, 3, 7])
def test_short_cycle_has_its_perron_root_and_vector(n):
    """The dense path (below DENSE_MAX states) on a cycle: its n eigenvalues 0.9·e^{2πik/n} share the largest
    modulus, and the Perron root is the one of largest real part. Closed form as in the long cycle: ρ = 0.9,
    left Perron vector ∝ diag(D)."""
    C = sp.csr_matrix((np.full(n, 0.9), (np.arange(n), (np.arange(n) + 1) % n)), shape=(n, n))
    d = np.exp(np.random.default_rng(n).normal(size=n))
    A = (sp.diags(1.0 / d) @ C @ sp.diags(d)).tocsr()
    assert A.shape[0] <= tf.DENSE_MAX
    lam, v = tf.leading_left(A)
    assert lam == pytest.approx(0.9, abs=1e-12)
    np.testing.assert_allclose(v, d / d.sum(), rtol=1e-10)
    M = tf.transfer_matrix(tf.Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], 2), math.log(4) / 3)
    lam, v = tf.leading_left(
        M
    )  # the two-state chain at its root: eigenvalues ±1, ν_1 = ν_0 · ½e^κ, ν = (1, 2^(-1/3))/Σ
    assert lam == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(v, np.array([1.0, 2 ** (-1 / 3)]) / (1 + 2 ** (-1 / 3)), rtol=1e-10)
