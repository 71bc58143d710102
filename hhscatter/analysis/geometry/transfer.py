"""Transfer operators from sampled transitions: Ulam's method for open maps and true-time maps.

An open question of Burton, Dullin & Altmann (2023) (Sec. "Discussion and Conclusion"): "spectral approaches considering
Perron–Frobenius (or similar) operators acting on these densities". This module holds the pure
functions (no I/O, no integration): they take sample transitions that the engine computed.

Ulam's method
-------------
A partition of the section into boxes B_1 … B_n; from each box i a sample of points x_s (with weights
w_s ≥ 0 proportional to the reference measure m the boxes sample, see :func:`section_flux_density`), each
mapped once by the return map h to the box ``dst[s]`` of h(x_s) (−1: the orbit left Ω before returning)
with the return time T_s. Then

    M(κ)_ij = Σ_{s: i→j} w_s e^{κ T_s} / Σ_{s ∈ i} w_s           (:func:`transfer_matrix`)

P = M(0) is Ulam's matrix of the open map: row sums 1 − (leak of box i). Its spectral radius ρ(P) = e^{−κ_map}
gives the escape rate *per return* of the discrete map, Eq. (eqn:kappa_cmeasure_discrete). The flow's escape
rate κ (1/time) is the root of

    ρ(M(κ)) = 1                                                   (:func:`true_time_kappa`)

the discretised true-time relation Eq. (eqn:kappa_cmeasure_truetime), ∫_{Ω∖𝓔} e^{κT} dμ_c = 1 (escaping
points carry T = 0 there, which adds μ_c(𝓔) to both sides). Its left eigenvector ν (ν M(κ) = ν, Σν = 1) is the
*flux* c-measure of the flow on the section: the distribution of all section crossings of the surviving
ensemble in the asymptotic regime (:mod:`hhscatter.analysis.survival.cmeasure`). The sprinkler sample
(the *first* crossing after a late time t) is ν pushed forward with the weight (e^{κT} − 1)/κ
(:func:`sprinkler_weights`); the left eigenvector of P is the c-measure of the discrete map (every return
weighted alike), a third measure. The three coincide only when T is constant.

Mixed phase space: a KAM island is invariant, so the boxes inside it form a *closed* communicating class of
the transition graph (no leak, no edge out) with eigenvalue 1, and ρ(M(κ)) > 1 for every κ > 0.
:func:`communicating_classes` finds the classes (strongly connected components, scipy.sparse.csgraph); the
escape rate of the chaotic saddle is the root on the largest *open* class (:func:`saddle_class`).

Dissipative ensembles: states are (box, energy bin) and the return times are binned into lags of ``dt``
(:func:`lag_kernels`); :func:`propagate` carries the crossing density n(t) forward return by return,
:func:`survival_from_crossings` gives P(t) from it and the probability that the next event lies beyond a lag, and
:func:`first_crossing_after` the distribution of the first crossing after a time t*.

Eigenvalues: scipy.sparse.linalg.eigs (ARPACK) for the leading eigenpair of a sparse matrix, dense LAPACK
(scipy.linalg.eig) below :data:`DENSE_MAX` states; roots by scipy.optimize.brentq. No hand-written solver.

Example
-------
>>> import numpy as np
>>> src, dst, T = np.array([0, 0, 1, 1]), np.array([1, -1, 0, -1]), np.array([1.0, 1.0, 2.0, 2.0])
>>> tr = Transitions(src, dst, T, n_states=2)
>>> bool(round(true_time_kappa(tr), 6) == round(-np.log(0.25) / 3.0, 6))
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp
from scipy import optimize
from scipy.sparse import csgraph
from scipy.sparse.linalg import eigs

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "DENSE_MAX",
    "ClassInfo",
    "Transitions",
    "bootstrap_kappa",
    "box_index",
    "capped_share",
    "communicating_classes",
    "first_crossing_after",
    "first_crossing_weights",
    "lag_kernels",
    "leading_left",
    "map_escape_rate",
    "propagate",
    "saddle_class",
    "saddle_measure",
    "section_flux_density",
    "spectral_radius",
    "sprinkler_weights",
    "survival_from_crossings",
    "transfer_matrix",
    "true_time_kappa",
]

DENSE_MAX = 64  # below this many states the dense LAPACK eigensolver is used (ARPACK needs k < n − 1)


@dataclass(frozen=True)
class Transitions:
    """Transitions(src, dst, T, n_states, w=None): sampled one-step transitions of a (true-time) map.

    ``src`` (int, in [0, n_states)): the box of each sample point; ``dst``: the box of its image, −1 if
    the point left before returning (escape; any negative value); ``T``: the return time (time units;
    ignored for escapes); ``w``: the sample weight (reference measure of the boxes, default 1).
    """

    src: np.ndarray
    dst: np.ndarray
    T: np.ndarray
    n_states: int
    w: np.ndarray | None = None

    def __post_init__(self):
        src = np.asarray(self.src, dtype=np.int64).ravel()
        dst = np.asarray(self.dst, dtype=np.int64).ravel()
        T = np.asarray(self.T, dtype=float).ravel()
        w = np.ones(src.size) if self.w is None else np.asarray(self.w, dtype=float).ravel()
        n = int(self.n_states)
        if not (src.size == dst.size == T.size == w.size):
            raise ConfigError(
                f"src, dst, T, w must have one entry per sample, got sizes {src.size}, {dst.size}, {T.size}, {w.size}"
            )
        if src.size and (src.min() < 0 or src.max() >= n):
            raise ConfigError(f"src must lie in [0, n_states = {n})")
        if dst.size and dst.max() >= n:
            raise ConfigError(f"dst must be < n_states = {n} (negative: escaped)")
        if np.any(~np.isfinite(w)) or np.any(w < 0):
            raise ConfigError("weights w must be finite and ≥ 0")
        ret = dst >= 0
        if np.any(~np.isfinite(T[ret])) or np.any(T[ret] <= 0):
            raise ConfigError("return times T of returning samples must be finite and > 0")
        object.__setattr__(self, "src", src)
        object.__setattr__(self, "dst", np.where(dst < 0, -1, dst))
        object.__setattr__(self, "T", T)
        object.__setattr__(self, "w", w)
        object.__setattr__(self, "n_states", n)

    @property
    def row_weight(self) -> np.ndarray:
        """Σ_{s ∈ i} w_s per state i (0 for a state without samples)."""
        return np.bincount(self.src, weights=self.w, minlength=self.n_states)

    @property
    def leak(self) -> np.ndarray:
        """Weighted share of each state's samples that escape (NaN for a state without samples)."""
        esc = np.bincount(self.src[self.dst < 0], weights=self.w[self.dst < 0], minlength=self.n_states)
        with np.errstate(invalid="ignore", divide="ignore"):
            return esc / self.row_weight

    def subset(self, keep) -> Transitions:
        """subset(keep) -> Transitions on the states where ``keep`` (bool, n_states) holds, renumbered;
        samples from dropped states are removed, samples *into* dropped states become escapes."""
        keep = np.asarray(keep, dtype=bool)
        new = np.full(self.n_states, -1, dtype=np.int64)
        new[keep] = np.arange(int(keep.sum()))
        s = keep[self.src]
        d = np.where(self.dst[s] >= 0, new[np.maximum(self.dst[s], 0)], -1)
        return Transitions(new[self.src[s]], d, self.T[s], int(keep.sum()), self.w[s])


def _transitions(tr, name: str = "tr") -> Transitions:
    """``tr`` if it is a :class:`Transitions`."""
    if not isinstance(tr, Transitions):
        raise ConfigError(f"{name} must be Transitions (sampled one-step transitions), got {type(tr).__name__}")
    return tr


def _matrix(A, name: str = "A", *, square: bool = True):
    """``A`` as a sparse matrix of finite numbers ≥ 0 (square if ``square``; at least one row)."""
    if not sp.issparse(A):
        values = check.numbers(A, name)
        if np.ndim(A) != 2:
            raise ConfigError(f"{name} must be a 2-D matrix, got {np.ndim(A)} dimension(s)")
    elif A.shape[0] == 0 or not np.all(np.isfinite(A.data)):
        raise ConfigError(f"{name} must be a non-empty matrix of finite numbers")
    else:
        values = A.data
    if values.size and values.min() < 0:
        raise ConfigError(f"{name} must be non-negative")
    if square and A.shape[0] != A.shape[1]:
        raise ConfigError(f"{name} must be square, got shape {A.shape}")
    return A


def _lag_kernel(K, n: int, L: int, of: str) -> None:
    """``K`` is the lag kernel of ``n`` states over ``L`` lags: a non-negative (n, n·L) matrix (``of``: the argument
    that gave n)."""
    _matrix(K, "K", square=False)
    if K.shape != (n, n * L):
        raise ConfigError(
            f"K must have shape (states, states × L) = ({n}, {n * L}) for the {n} states of {of}, got {K.shape}"
        )


def _crossings(c, name: str = "crossings", n: int | None = None) -> np.ndarray:
    """``c`` as a (steps, states) array of finite numbers ≥ 0 (``n`` states if given)."""
    check.numbers(c, name, minimum=0.0)
    c = np.asarray(c, dtype=float)
    if c.ndim != 2 or (n is not None and c.shape[1] != n):
        want = "states" if n is None else f"{n} states"
        raise ConfigError(f"{name} must be a (steps, {want}) array, got shape {c.shape}")
    return c


def transfer_matrix(tr: Transitions, kappa: float = 0.0) -> sp.csr_matrix:
    """transfer_matrix(tr, kappa=0) -> csr M(κ), M_ij = Σ_{s: i→j} w_s e^{κT_s} / Σ_{s∈i} w_s (1/time: κ).

    κ = 0 gives Ulam's matrix P of the open map (sub-stochastic rows). States without samples have
    empty rows.

    Examples
    --------
    Two boxes that send half their samples to each other (return times 1 and 2) and lose the other half:

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> transfer_matrix(tr).toarray().tolist()
    [[0.0, 0.5], [0.5, 0.0]]
    >>> np.round(transfer_matrix(tr, kappa=math.log(2)).toarray(), 6).tolist()  # × e^{κT} = 2 and 4
    [[0.0, 1.0], [2.0, 0.0]]
    """
    _transitions(tr)
    check.number(kappa, "kappa")
    ret = tr.dst >= 0
    rw = tr.row_weight
    inv = np.divide(1.0, rw, out=np.zeros_like(rw), where=rw > 0)
    val = tr.w[ret] * inv[tr.src[ret]]
    if kappa != 0.0:
        val = val * np.exp(kappa * tr.T[ret])
    M = sp.csr_matrix((val, (tr.src[ret], tr.dst[ret])), shape=(tr.n_states, tr.n_states))
    M.eliminate_zeros()  # a sample of weight 0 is no edge of the transition graph
    return M


def _dense_leading(A):
    """(λ, left vector) of the Perron root of a non-negative matrix by LAPACK: the eigenvalue of largest real part,
    as in :func:`_arpack_leading` (a cycle's eigenvalues ρ·e^{2πik/n} all have the largest modulus)."""
    vals, left = scipy.linalg.eig(np.asarray(A.todense() if sp.issparse(A) else A, dtype=float).T)
    k = int(np.argmax(vals.real))
    return vals[k], left[:, k]


def _arpack_leading(A, tol: float, *, vector: bool):
    """(λ, left vector or None) of the Perron root of a non-negative sparse A by ARPACK.

    The Perron root ρ is the eigenvalue of largest *real part* (Re λ ≤ |λ| ≤ ρ, with Re λ = ρ only at
    λ = ρ), so ARPACK is asked for ``which="LR"``. Largest *magnitude* ("LM") is ambiguous on these
    matrices: Ulam matrices of the three-exit section have eigenvalues close to ρ·e^{±2πi/3}, and "LM"
    returned one of them (|λ| 0.9335 against ρ = 0.93495 at E = 0.2, box 0.00625) or stalled. ARPACK starts
    from the uniform vector. A stall is retried with 64 Lanczos vectors instead of 20; then a ValueError
    is raised (never a wrong root).
    """
    At = A.T.tocsr()
    n = A.shape[0]
    # start from the uniform vector: it overlaps every non-negative Perron vector, and fixes ARPACK's
    # otherwise random start, so that the result does not depend on earlier calls in the process
    kw = dict(
        k=1,
        which="LR",
        tol=tol,
        maxiter=max(2000, 20 * n),
        return_eigenvectors=vector,
        v0=np.full(n, 1.0 / math.sqrt(n)),
    )
    try:
        out = eigs(At, **kw)
    except sp.linalg.ArpackNoConvergence:
        try:
            out = eigs(At, ncv=min(n - 1, 64), **kw)
        except sp.linalg.ArpackNoConvergence as e:
            raise ConfigError(
                f"ARPACK found no Perron root of this {n}-state matrix (largest real part, "
                "64 Lanczos vectors): its spectrum is too close to a circle"
            ) from e
    if vector:
        vals, vecs = out
        return vals[0], vecs[:, 0]
    return out[0], None


def leading_left(A, *, tol: float = 1e-12) -> tuple[float, np.ndarray]:
    """leading_left(A) -> (λ, v): the Perron root of a non-negative square matrix and its left eigenvector.

    v A = λ v, normalised to v ≥ 0 and Σ v = 1 (a probability vector; ARPACK and LAPACK return an
    eigenvector of arbitrary sign and scale). λ = ρ(A) is real for a non-negative matrix; the eigensolver
    returns it with a tiny imaginary part, which is dropped (a sizable one is an error). A zero matrix
    gives (0, uniform). Uses ARPACK (scipy.sparse.linalg.eigs, largest real part) above
    :data:`DENSE_MAX` states, dense LAPACK below.

    Examples
    --------
    A stochastic matrix: λ = 1 and v its stationary distribution, (2/7, 5/7) from 0.5 v_0 = 0.2 v_1.

    >>> lam, v = leading_left(np.array([[0.5, 0.5], [0.2, 0.8]]))
    >>> round(lam, 6), np.round(v, 4).tolist()
    (1.0, [0.2857, 0.7143])
    """
    _matrix(A)
    check.number(tol, "tol", positive=True)
    A = sp.csr_matrix(A)
    n = A.shape[0]
    if A.shape != (n, n):
        raise ConfigError(f"A must be square, got shape {A.shape}")
    if A.nnz and A.data.min() < 0:
        raise ConfigError("A must be non-negative")
    if A.nnz == 0:
        return 0.0, np.full(n, 1.0 / n)
    if n <= DENSE_MAX:
        lam, v = _dense_leading(A)
    else:
        lam, v = _arpack_leading(A, tol, vector=True)
    if abs(lam.imag) > 1e-8 * max(abs(lam.real), 1e-300):
        raise ConfigError(f"leading eigenvalue {lam} is not real: A is not non-negative or ARPACK failed")
    # a Perron vector has one phase: rotate it onto the positive reals
    j = int(np.argmax(np.abs(v)))
    v = (v * np.exp(-1j * np.angle(v[j]))).real
    v = np.where(np.abs(v) < 1e-14 * np.abs(v).max(), 0.0, v)
    if v.min() < -1e-8 * v.max():
        raise ConfigError(
            "leading eigenvector has both signs: A is reducible with several Perron roots; "
            "restrict it to one communicating class (communicating_classes)"
        )
    v = np.clip(v, 0.0, None)
    return float(lam.real), v / v.sum()


def spectral_radius(A) -> float:
    """spectral_radius(A) -> ρ(A) of a non-negative square matrix (see :func:`leading_left`).

    Examples
    --------
    The eigenvalues of [[0, 4], [1, 0]] are ±2:

    >>> round(spectral_radius(np.array([[0.0, 4.0], [1.0, 0.0]])), 6)
    2.0
    """
    _matrix(A)
    A = sp.csr_matrix(A)
    if A.nnz == 0:
        return 0.0
    if A.shape[0] <= DENSE_MAX:
        return float(abs(_dense_leading(A)[0]))
    return float(abs(_arpack_leading(A, 1e-12, vector=False)[0]))


def map_escape_rate(tr: Transitions) -> float:
    """map_escape_rate(tr) -> −ln ρ(P): the discrete map's escape rate per return, Eq. (eqn:kappa_cmeasure_discrete).

    Examples
    --------
    Half of every box's samples return, half escape: ρ(P) = ½, a rate ln 2 = 0.6931 per return.

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> round(map_escape_rate(tr), 4)
    0.6931
    """
    _transitions(tr)
    rho = spectral_radius(transfer_matrix(tr, 0.0))
    return -math.log(rho) if rho > 0 else math.inf


def true_time_kappa(tr: Transitions, *, xtol: float = 1e-13) -> float:
    """true_time_kappa(tr) -> κ (1/time), the root of ρ(M(κ)) = 1 (brentq), Eq. (eqn:kappa_cmeasure_truetime).

    ρ(M(κ)) grows monotonically with κ; a root κ > 0 exists iff ρ(P) < 1 (the states leak). A closed set
    of states (ρ(P) = 1, e.g. a KAM island) has no root: restrict ``tr`` to the saddle's class first
    (:func:`saddle_class`); ValueError otherwise.

    Examples
    --------
    Half return, after T = 1 from box 0 and T = 2 from box 1: ρ(M(κ))² = ¼ e^{κ} e^{2κ} = 1 at κ = ln 4 / 3.

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> round(true_time_kappa(tr), 6), round(math.log(4) / 3, 6)
    (0.462098, 0.462098)
    """

    _transitions(tr)
    check.number(xtol, "xtol", positive=True)

    def h(k):
        return math.log(spectral_radius(transfer_matrix(tr, k)))

    if spectral_radius(transfer_matrix(tr, 0.0)) == 0:
        raise ConfigError("tr: no sample returns to a state that is left again (ρ(P) = 0): κ is not finite")
    h0 = h(0.0)
    if not h0 < -1e-12:
        raise ConfigError(
            f"ρ(P) = {math.exp(h0):.12g} ≥ 1: no escape, no root κ > 0 (closed states: "
            "remove them with communicating_classes / saddle_class)"
        )
    ret = tr.dst >= 0
    t_mean = float(np.average(tr.T[ret], weights=tr.w[ret])) if ret.any() else 1.0
    hi = -h0 / max(t_mean, 1e-300)
    while h(hi) <= 0:
        hi *= 2.0
        if hi > 1e6:
            raise ConfigError("no root of ρ(M(κ)) = 1 below κ = 1e6")
    return float(optimize.brentq(h, 0.0, hi, xtol=xtol, rtol=1e-12))


def bootstrap_kappa(tr: Transitions, n_boot: int, rng=None) -> np.ndarray:
    """bootstrap_kappa(tr, n_boot, rng=None) -> n_boot replicates of the saddle's κ (1/time).

    Poisson bootstrap over the sample orbits (the independent unit: one orbit per sample): each replicate
    multiplies every sample's weight by an independent Poisson(1) count and solves ρ(M(κ)) = 1 again on the
    replicate's saddle class (:func:`saddle_class`, :func:`true_time_kappa`). Their std is the statistical
    error of κ; the discretisation bias of the boxes is not in it.

    Examples
    --------
    2000 samples of two boxes, each returning (T = 1) with probability ½; in this sample 52.7 % return, so
    κ = −ln 0.527 = 0.64 (ln 2 = 0.69 for an infinite one), with a statistical error near
    √((1 − p)/(p n)) = √(1/2000) = 0.022:

    >>> rng = np.random.default_rng(0)
    >>> src = rng.integers(0, 2, 2000)
    >>> tr = Transitions(src, np.where(rng.random(2000) < 0.5, 1 - src, -1), np.ones(2000), n_states=2)
    >>> k = bootstrap_kappa(tr, 20, rng=1)
    >>> round(true_time_kappa(tr), 2), round(float(k.std()), 2)
    (0.64, 0.02)
    """
    _transitions(tr)
    check.count(n_boot, "n_boot", 0)
    gen = np.random.default_rng(rng)
    out = np.empty(int(n_boot))
    for b in range(int(n_boot)):
        rep = Transitions(tr.src, tr.dst, tr.T, tr.n_states, tr.w * gen.poisson(1.0, tr.src.size))
        keep, _ = saddle_class(rep)
        out[b] = true_time_kappa(rep.subset(keep))
    return out


@dataclass(frozen=True)
class ClassInfo:
    """One communicating class: ``label``, ``size`` (states), ``weight`` (sample weight in it), ``closed``
    (no escape and no transition out: invariant under the sampled map), ``leak`` (weighted escape share
    of its samples), ``out`` (weighted share going to other classes)."""

    label: int
    size: int
    weight: float
    closed: bool
    leak: float
    out: float


def communicating_classes(tr: Transitions) -> tuple[np.ndarray, list[ClassInfo]]:
    """communicating_classes(tr) -> (labels (n_states,), [ClassInfo …] largest weight first).

    The strongly connected components of the transition graph (scipy.sparse.csgraph.connected_components,
    connection='strong'). A *closed* class keeps all its samples (an invariant set of the sampled map:
    ρ = 1 on it, e.g. a KAM island resolved by the boxes).

    Examples
    --------
    Boxes 0 and 1 exchange orbits and leak half of them; box 2 maps onto itself (an island):

    >>> tr = Transitions([0, 0, 1, 1, 2], [1, -1, 0, -1, 2], np.ones(5), n_states=3)
    >>> labels, classes = communicating_classes(tr)
    >>> labels.tolist(), [(c.size, c.closed, c.leak) for c in classes]
    ([0, 0, 1], [(2, False, 0.5), (1, True, 0.0)])
    """
    _transitions(tr)
    P = transfer_matrix(tr, 0.0)
    _, labels = csgraph.connected_components(P, directed=True, connection="strong")
    ret = tr.dst >= 0
    same = np.zeros(tr.src.size, dtype=bool)
    same[ret] = labels[tr.src[ret]] == labels[tr.dst[ret]]
    lab_s = labels[tr.src]
    nl = int(labels.max()) + 1 if labels.size else 0
    W = np.bincount(lab_s, weights=tr.w, minlength=nl)
    esc = np.bincount(lab_s[~ret], weights=tr.w[~ret], minlength=nl)
    out = np.bincount(lab_s[ret & ~same], weights=tr.w[ret & ~same], minlength=nl)
    size = np.bincount(labels, minlength=nl)
    infos = [
        ClassInfo(
            int(c),
            int(size[c]),
            float(W[c]),
            bool(W[c] > 0 and esc[c] == 0 and out[c] == 0),
            float(esc[c] / W[c]) if W[c] > 0 else math.nan,
            float(out[c] / W[c]) if W[c] > 0 else math.nan,
        )
        for c in range(nl)
    ]
    infos.sort(key=lambda c: (-c.weight, c.label))
    return labels, infos


def saddle_class(tr: Transitions) -> tuple[np.ndarray, list[ClassInfo]]:
    """saddle_class(tr) -> (keep (bool, n_states), classes): the states of the chaotic saddle's class.

    The largest open class (not closed; most states, then most sample weight). Closed classes (invariant:
    KAM islands, eigenvalue 1) are excluded; the escape rate of the saddle is :func:`true_time_kappa` of
    ``tr.subset(keep)``. (By states, not weight: a transient box whose few samples carry a large weight is
    a class of its own with ρ = 0.)

    Examples
    --------
    The island (box 2) is left out; the saddle's κ = ln 2 per unit time (half return after T = 1):

    >>> tr = Transitions([0, 0, 1, 1, 2], [1, -1, 0, -1, 2], np.ones(5), n_states=3)
    >>> keep, classes = saddle_class(tr)
    >>> keep.tolist(), round(true_time_kappa(tr.subset(keep)), 4)
    ([True, True, False], 0.6931)
    """
    _transitions(tr)
    labels, infos = communicating_classes(tr)
    open_ = sorted((c for c in infos if not c.closed and c.weight > 0), key=lambda c: (-c.size, -c.weight, c.label))
    if not open_:
        raise ConfigError("every communicating class is closed: no escape")
    return labels == open_[0].label, infos


def saddle_measure(tr: Transitions, kappa: float, keep) -> tuple[np.ndarray, float]:
    """saddle_measure(tr, κ, keep) -> (ν over all states, λ): the saddle's c-measure on the section.

    The left Perron vector of M(κ) on the saddle's class ``keep`` and every state downstream of it (reachable
    from it: orbits on their way out cross the section too), closed classes left out (an island's vector
    would win with eigenvalue ≥ 1). At the root κ of the class, λ = 1. If a downstream class has a larger
    root (λ > 1: a sticky, nearly closed set), the vector is taken on ``keep`` alone and λ is reported.

    Examples
    --------
    Boxes 0 and 1 form the saddle (κ = ln 2); box 1 also feeds box 2, which every orbit leaves: ν = ν M(κ) with
    M(κ) = 2P gives ν_0 = ν_1 = ν_2 (orbits on their way out cross the section too).

    >>> tr = Transitions([0, 0, 1, 1, 2], [1, -1, 0, 2, -1], np.ones(5), n_states=3)
    >>> keep, _ = saddle_class(tr)
    >>> nu, lam = saddle_measure(tr, math.log(2), keep)
    >>> np.round(nu, 4).tolist(), round(lam, 6)
    ([0.3333, 0.3333, 0.3333], 1.0)
    """
    _transitions(tr)
    check.number(kappa, "kappa")
    keep = check.mask(keep, "keep", tr.n_states)
    if not keep.any():
        raise ConfigError("keep must select at least one state")
    labels, infos = communicating_classes(tr)
    closed = np.isin(labels, [c.label for c in infos if c.closed])
    A = (transfer_matrix(tr) > 0).astype(np.int8).T.tocsr()  # A[j, i] = 1: an edge i → j
    reach = keep.copy()
    while True:
        new = reach | (A @ reach.astype(np.int8) > 0)
        if new.sum() == reach.sum():
            break
        reach = new
    sel = reach & ~closed
    lam, v = leading_left(transfer_matrix(tr.subset(sel), kappa))
    if lam > 1.0 + 1e-6:
        sel = keep
        lam, v = leading_left(transfer_matrix(tr.subset(sel), kappa))
    nu = np.zeros(tr.n_states)
    nu[sel] = v
    return nu, lam


def sprinkler_weights(tr: Transitions, nu: np.ndarray, kappa: float) -> np.ndarray:
    """sprinkler_weights(tr, ν, κ) -> weight of each sample's image point in the first-crossing measure.

    The first crossing after a late time t of the surviving flow ensemble, whose crossings at x occur at
    rate ∝ ν(x) e^{−κt}, lands at h(x) with weight ν(x)·(e^{κT(x)} − 1)/κ (the crossing at x happened in
    [t − T(x), t)); per sample: ν_src · w_s/W_src · (e^{κT_s} − 1)/κ, 0 for escapes. κ = 0: the limit T.

    Examples
    --------
    ν = (½, ½), half of each box's samples return after T = 1: each returning image weighs
    ½ · ½ · (e^{κ} − 1)/κ = 1/(4 ln 2) = 0.3607 at κ = ln 2, escapes 0.

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], np.ones(4), n_states=2)
    >>> np.round(sprinkler_weights(tr, [0.5, 0.5], math.log(2)), 4).tolist()
    [0.3607, 0.0, 0.3607, 0.0]
    """
    _transitions(tr)
    if check.numbers(nu, "nu", minimum=0.0).size != tr.n_states:
        raise ConfigError(f"nu must have one value per state: {np.size(nu)} != {tr.n_states}")
    check.number(kappa, "kappa")
    nu = np.asarray(nu, dtype=float)
    rw = tr.row_weight
    inv = np.divide(1.0, rw, out=np.zeros_like(rw), where=rw > 0)
    ret = tr.dst >= 0
    g = np.where(ret, np.expm1(kappa * tr.T) / kappa if kappa > 0 else tr.T, 0.0)
    return nu[tr.src] * tr.w * inv[tr.src] * g


def section_flux_density(model, x, y, energy, *, h: float = 1e-6):
    """section_flux_density(model, x, y, E) -> |ṗ_r|/v: the density, in (x, y), of the invariant measure of
    the return map on the section ṙ = 0, φ̇ > 0 at energy E (1/length², unnormalised).

    The flux of the Liouville measure δ(H − E) through the section g = x p_x + y p_y = 0:
    |ġ| δ(g) δ(H − E) dx dy dp, integrated over the momenta (tangential, |p| = v = √(2(E − V))), gives
    |ġ|/(r v) dx dy with ġ = v² − r ∂_r V, i.e. |v²/r − ∂_r V| / v = |ṗ_r|/v. It is the measure the return
    map preserves (the symplectic form restricted to the section), so the boxes are sampled with it.
    ∂_r V by a central difference of ``model.potential`` along the ray (relative step h): no model
    constants here. 0 where V ≥ E or r = 0.

    Examples
    --------
    The harmonic well V = r²/2 at E = 1, r = ½: v² = 2(1 − ⅛) = 7/4, |v²/r − r| / v = 3/√(7/4) = 2.2678; 0 where
    V ≥ E.

    >>> from hhscatter.model import HenonHeiles
    >>> np.round(section_flux_density(HenonHeiles(lam=1e-12), [0.5, 2.0], [0.0, 0.0], 1.0), 4).tolist()
    [2.2678, 0.0]
    """
    _checks.potential(model)
    check.numbers(x, "x")
    check.numbers(y, "y")
    check.numbers(energy, "energy")
    check.number(h, "h", positive=True)
    try:
        np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(energy))
    except ValueError:
        raise ConfigError(
            f"x, y and energy must have one value per point (shapes {np.shape(x)}, {np.shape(y)}, {np.shape(energy)})"
        ) from None
    x, y, E = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(energy, float))
    r = np.hypot(x, y)
    V = model.potential(x, y)
    ok = (V < E) & (r > 0)
    out = np.zeros(x.shape)
    xr, yr, rr, Er = x[ok], y[ok], r[ok], E[ok]
    d = h * rr
    dVdr = (model.potential(xr * (1 + h), yr * (1 + h)) - model.potential(xr * (1 - h), yr * (1 - h))) / (2 * d)
    v2 = 2.0 * (Er - V[ok])
    out[ok] = np.abs(v2 / rr - dVdr) / np.sqrt(v2)
    return out


def box_index(x, y, extent, box: float) -> tuple[np.ndarray, int, int]:
    """box_index(x, y, extent, box) -> (flat index (−1 outside extent), nx, ny): squares of side ``box``
    anchored at (x0, y0) of ``extent`` = (x0, x1, y0, y1); index = iy·nx + ix.

    Examples
    --------
    Boxes of side ½ on the unit square, numbered row by row (iy·nx + ix); −1 outside:

    >>> box_index([0.6, 0.2, 1.5], [0.1, 0.7, 0.0], (0, 1, 0, 1), 0.5)
    (array([ 1,  2, -1]), 2, 2)
    """
    if check.numbers(x, "x", min_size=0).size != check.numbers(y, "y", min_size=0).size:
        raise ConfigError(f"x and y must have one value per point ({np.size(x)} vs {np.size(y)})")
    _checks.extent(extent)
    check.number(box, "box", positive=True)
    x0, x1, y0, y1 = (float(v) for v in extent)
    nx, ny = int(math.ceil((x1 - x0) / box - 1e-9)), int(math.ceil((y1 - y0) / box - 1e-9))
    ix = np.floor((np.asarray(x, float) - x0) / box).astype(np.int64)
    iy = np.floor((np.asarray(y, float) - y0) / box).astype(np.int64)
    inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    return np.where(inside, iy * nx + ix, -1), nx, ny


# ---------------------------------------------------------------------------
# dissipative ensembles: the operator carried forward in time
# ---------------------------------------------------------------------------
def lag_kernels(tr: Transitions, t_end, dt: float, max_lag: int | None = None) -> tuple[sp.csr_matrix, np.ndarray, int]:
    """lag_kernels(tr, t_end, dt, max_lag=None) -> (K, H, L): the true-time operator binned in time steps of ``dt``.

    Each sample's return time T_s becomes a lag ℓ_s = max(1, round(T_s/dt)), at most ``max_lag`` (a longer
    return arrives early, at max_lag·dt: it bounds the memory, n·L per step; report the weight it moves
    with :func:`capped_share`); ``K`` (n × n·L, csr) holds
    the blocks K_ℓ (ℓ = 1 … L side by side): (K_ℓ)_ij = Σ_{s: i→j, ℓ_s = ℓ} w_s / W_i. ``t_end`` is each
    sample's time to its next event (return, escape, settling); H (L + 1, n) is the weighted share of
    state i's samples whose next event lies beyond lag ℓ, H_ℓ,i = Σ_{s ∈ i: t_end,s > ℓ dt} w_s / W_i
    (H has as many rows as the latest event needs; beyond them it is 0).

    Examples
    --------
    Box 0 returns to box 1 after T = 1 or escapes at t = 2; box 1 returns to box 0 after T = 2 or escapes at t = 3
    (dt = 1): K_1 holds 0 → 1, K_2 holds 1 → 0; H counts who is still on its way.

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> K, H, L = lag_kernels(tr, [1.0, 2.0, 2.0, 3.0], dt=1.0)
    >>> L, K.toarray().tolist()
    (2, [[0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 0.5, 0.0]])
    >>> H.T.tolist()  # box 0: all on their way at lag 0, half (the escapes at t = 2) at lag 1
    [[1.0, 0.5, 0.0, 0.0], [1.0, 1.0, 0.5, 0.0]]
    """
    _transitions(tr)
    t_end = _checks.values(t_end, "t_end", min_size=0)
    if t_end.size != tr.src.size:
        raise ConfigError("t_end must give one time per sample")
    if not np.all(np.isfinite(t_end[tr.dst < 0])):
        raise ConfigError("t_end must be finite for the samples that escape")
    check.number(dt, "dt", positive=True)
    if max_lag is not None:
        _checks.whole(max_lag, "max_lag")
    n = tr.n_states
    rw = tr.row_weight
    inv = np.divide(1.0, rw, out=np.zeros_like(rw), where=rw > 0)
    ret = tr.dst >= 0
    lag = np.maximum(1, np.rint(tr.T[ret] / dt).astype(np.int64))
    if max_lag is not None:
        lag = np.minimum(lag, int(max_lag))
    L = int(lag.max()) if lag.size else 1
    val = tr.w[ret] * inv[tr.src[ret]]
    K = sp.csr_matrix((val, (tr.src[ret], (lag - 1) * n + tr.dst[ret])), shape=(n, n * L))
    # H: share whose next event is later than ℓ·dt; returning samples end at their (binned) lag
    ends = np.where(ret, 0, np.rint(np.where(ret, 0.0, t_end) / dt).astype(np.int64))
    ends[ret] = lag
    Lh = int(ends.max()) if ends.size else 0
    H = np.zeros((Lh + 1, n))
    np.add.at(H, (ends, tr.src), tr.w * inv[tr.src])
    H = 1.0 - np.cumsum(H, axis=0)  # H[ℓ] = share with end > ℓ
    H[:, rw == 0] = 0.0
    return K, np.clip(H, 0.0, 1.0), L


def capped_share(tr: Transitions, dt: float, max_lag: int) -> float:
    """capped_share(tr, dt, max_lag) -> the share of the returning sample weight whose lag exceeds max_lag.

    Examples
    --------
    Of the two returns, the one after T = 2 exceeds a cap of one lag of dt = 1:

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> capped_share(tr, 1.0, 1), capped_share(tr, 1.0, 2)
    (0.5, 0.0)
    """
    _transitions(tr)
    check.number(dt, "dt", positive=True)
    check.number(max_lag, "max_lag", minimum=1.0)
    ret = tr.dst >= 0
    if not ret.any():
        return 0.0
    lag = np.rint(tr.T[ret] / dt)
    return float(tr.w[ret][lag > max_lag].sum() / tr.w[ret].sum())


def propagate(n0, K: sp.csr_matrix, L: int, n_steps: int) -> np.ndarray:
    """propagate(n0, K, L, n_steps) -> array (n_steps + 1, n): crossing density per time step.

    n(0) = n0 (the initial ensemble, on the section at t = 0); n(k) = Σ_ℓ n(k − ℓ) K_ℓ, one sparse product
    per step (every lag at once).

    Examples
    --------
    The two boxes of :func:`lag_kernels`, all orbits in box 0 at t = 0: half reach box 1 at step 1, a quarter
    box 0 at step 3 (lag 2), an eighth box 1 at step 4.

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> K, H, L = lag_kernels(tr, [1.0, 2.0, 2.0, 3.0], dt=1.0)
    >>> propagate([1.0, 0.0], K, L, 4).tolist()
    [[1.0, 0.0], [0.0, 0.5], [0.0, 0.0], [0.25, 0.0], [0.0, 0.125]]
    """
    n0 = check.numbers(n0, "n0", minimum=0.0)
    n = n0.size
    L = _checks.whole(L, "L")
    n_steps = _checks.whole(n_steps, "n_steps", 0)
    _lag_kernel(K, n, L, "n0")
    out = np.zeros((n_steps + L + 1, n))
    out[0] = n0
    Kt = K.T.tocsr()
    for k in range(n_steps):
        if not out[k].any():
            continue
        out[k + 1 : k + 1 + L] += (Kt @ out[k]).reshape(L, n)
    return out[: n_steps + 1]


def survival_from_crossings(crossings: np.ndarray, H: np.ndarray) -> np.ndarray:
    """P(t_k), k = 0 … n_steps, of an ensemble propagated on the boxes: the share not yet gone.

    An orbit is alive at step k if its last crossing was at k' ≤ k and its next event lies beyond k − k':
    P(k) = Σ_{k' ≤ k} n(k') · H_{k − k'} (H beyond its last row: 0), one convolution per state
    (scipy.signal.fftconvolve).

    Examples
    --------
    The two boxes of :func:`lag_kernels` from box 0: every orbit is on its way until t = 2, when half escape; at
    t = 4 half of the rest have escaped from box 1 (t = 1 + 3) and a quarter are still alive.

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> K, H, L = lag_kernels(tr, [1.0, 2.0, 2.0, 3.0], dt=1.0)
    >>> np.round(survival_from_crossings(propagate([1.0, 0.0], K, L, 4), H), 6).tolist()
    [1.0, 1.0, 0.5, 0.5, 0.25]
    """
    from scipy.signal import fftconvolve  # deferred: scipy loads on first use

    crossings = _crossings(crossings)
    steps, n = crossings.shape
    H = _crossings(H, "H", n)
    Hs = np.zeros((steps, n))
    m = min(steps, H.shape[0])
    Hs[:m] = H[:m]
    live = np.flatnonzero(crossings.any(axis=0) & Hs.any(axis=0))
    P = np.zeros(steps)
    for i in range(0, live.size, 1024):  # a block of states at a time bounds the FFT's memory
        cols = live[i : i + 1024]
        P += fftconvolve(crossings[:, cols], Hs[:, cols], axes=0)[:steps].sum(axis=1)
    return np.clip(P, 0.0, None)


def first_crossing_weights(crossings: np.ndarray, tr: Transitions, dt: float, k_star: int) -> np.ndarray:
    """first_crossing_weights(crossings, tr, dt, k*) -> weight of each sample's image point in the first
    crossing at or after step k* (0 for escapes): ν-weighted like :func:`first_crossing_after`, per sample,
    so that the images give the distribution below the box scale. Σ over samples into j = that function's
    entry j.

    Examples
    --------
    The same as :func:`first_crossing_after`, per sample: the return of box 1 to box 0 (sample 2) carries it all.

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> K, H, L = lag_kernels(tr, [1.0, 2.0, 2.0, 3.0], dt=1.0)
    >>> first_crossing_weights(propagate([1.0, 0.0], K, L, 4), tr, 1.0, 2).tolist()
    [0.0, 0.0, 0.25, 0.0]
    """
    _transitions(tr)
    crossings = _crossings(crossings, n=tr.n_states)
    check.number(dt, "dt", positive=True)
    k_star = _checks.whole(k_star, "k_star", 0)
    if k_star > crossings.shape[0]:
        raise ConfigError(f"k_star must be at most the steps of crossings ({crossings.shape[0]}), got {k_star}")
    cs = np.vstack([np.zeros((1, crossings.shape[1])), np.cumsum(crossings[:k_star], axis=0)])
    ret = tr.dst >= 0
    lag = np.maximum(1, np.rint(np.where(ret, tr.T, dt) / dt).astype(np.int64))
    lo = np.maximum(0, k_star - lag)
    C = cs[k_star, tr.src] - cs[lo, tr.src]
    rw = tr.row_weight
    inv = np.divide(1.0, rw, out=np.zeros_like(rw), where=rw > 0)
    return np.where(ret, C * tr.w * inv[tr.src], 0.0)


def first_crossing_after(crossings: np.ndarray, K: sp.csr_matrix, L: int, k_star: int) -> np.ndarray:
    """first_crossing_after(crossings, K, L, k*) -> unnormalised distribution over states of the first crossing
    at or after step k* of every orbit alive then: Σ_ℓ Σ_{k* − ℓ ≤ k' < k*} n(k') K_ℓ.

    Examples
    --------
    The two boxes of :func:`lag_kernels` from box 0: the orbits alive at step 2 (the half in box 1 since step 1)
    cross next in box 0, at step 3, a quarter of them returning:

    >>> tr = Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> K, H, L = lag_kernels(tr, [1.0, 2.0, 2.0, 3.0], dt=1.0)
    >>> first_crossing_after(propagate([1.0, 0.0], K, L, 4), K, L, 2).tolist()
    [0.25, 0.0]
    """
    crossings = _crossings(crossings)
    n = crossings.shape[1]
    L = _checks.whole(L, "L")
    k_star = _checks.whole(k_star, "k_star", 0)
    _lag_kernel(K, n, L, "crossings")
    out = np.zeros(n)
    Kt = K.T.tocsr()
    for kp in range(max(0, k_star - L), k_star):
        if not crossings[kp].any():
            continue
        blocks = (Kt @ crossings[kp]).reshape(L, n)
        first = k_star - kp  # lag ℓ ≥ k* − k' arrives at or after k*
        out += blocks[first - 1 :].sum(axis=0)
    return out
