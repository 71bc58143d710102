"""Events and outcome rules, declared once (paper App. "Escape Condition").

``scene_events(scene) -> tuple[EventSpec, ...]`` is the one place where the
events of a scene are declared: each is plain data (name, direction, the
expression whose root is the event, what it is for). Every driver builds its
heyoka events from it through :mod:`hhscatter.integrate.integrators`: the batch engine
(:mod:`hhscatter.integrate.engine`), the scalar reference driver
(:func:`hhscatter.integrate.engine.simulate_orbit`, which the benchmarks and stress tests use in long
double or real128) and every continuation. No other module constructs a heyoka event.

All events are heyoka *terminal* events with a callback: heyoka then ends the
step exactly at the root, so the state and the orbit time of every recorded
event are the integrator's own (no dense-output evaluation, no rounding on a
lane clock: event times and states do not depend on how orbits share lanes).
The callback decides, by the outcome rules below, whether the orbit ends.

| event (rule) | dir. | expression (root) | role |
|---|---|---|---|
| escape | + | r² − r_esc² | conservative: escaped at the first outward crossing (t_end = its root) |
| closure | − | H − E_c | dissipative: settled if r ≤ r_s there, else escaped at the last outward r_esc crossing |
| far | + | r²/r_far² − 1 | dissipative, and conservative follow: the orbit is gone (never returns) |
| resc | any | r² − r_esc² | dissipative: remembers the last outward crossing (the escape time) |
| radius_k (radius) | any | r² − R_k² | follow: crossings of the radii R_k and r_esc (table ``crossings``); the outward r_esc one is the escape |
| section | any | g·(x p_x + y p_y − 10⁻³⁰⁰) + (1 − g) | ṙ = 0, kept where φ̇ > 0 and the window admits it; g = 0/1 per lane (runtime parameter) switches it off; a late window compiles it only into the orbits' second phase (two_phase) |
| clock | − | σ  (dσ/dt = −1/G) | orbit-time schedule: opens/closes the section window at t_from/t_to |

Normalisation: event values enter heyoka's step-size control, so each is
O(1) where it matters (r²/r_far² − 1 rather than r² − r_far²; the clock σ
counts down in [0, 1] rather than carrying the orbit time, whose size would
loosen the tolerance of the whole state). There is never an event on the
integrator's time ``t − t_max``: time limits are propagation bounds.

Outcome rules (the paper's, App. "Escape Condition"):

* conservative: ``escaped`` at the first outward r_esc crossing; ``censored``
  at t_max;
* dissipative: the orbit is followed until E = E_c. Inside Ω (r ≤ r_s, the
  saddle distance) it is ``settled`` at that root (it can never leave);
  outside it is ``escaped``, with t_end its *last* outward r_esc crossing;
  an orbit that reaches r_far is escaped the same way; ``censored`` at t_max;
* ``stopped``: nothing more was needed from the orbit (a section window with
  ``stop = true`` is done); t_end is the stop time. Analyses treat it as
  censoring at t_end.
* noise (:mod:`hhscatter.integrate.noise`): the flow between kicks is Hamiltonian (the drag is in the
  Ornstein–Uhlenbeck step), with the conservative rule: ``escaped`` at the first outward r_esc crossing;
  E = E_c is no event (a heat bath lifts a settled orbit again); ``censored`` at t_max.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from hhscatter.outcomes import (  # re-exported for the engine
    CENSORED,
    ESCAPED,
    OUTCOMES,
    SETTLED,
    STOPPED,
)

# Every initial condition of the default (tangential) momentum lies on the section (x px + y py = 0 exactly in
# double). With the event value exactly 0 at the start of a step, heyoka's root
# isolation reported the root at t = 0 twice and lost the next crossing in the
# same (first) step. A constant offset of 1e-300 makes the start
# value non-zero; it moves a crossing by 1e-300/|d(x px + y py)/dt|. (Random-direction momenta
# (Scene.momentum = "random") start off the section: the first root is a real crossing, after T_INITIAL.)
SECTION_OFFSET = 1e-300
# Section crossings before T_INITIAL are the initial point itself. An orbit that starts on the section at an
# inflection of r (r̈ = 0 as well as ṙ = 0) touches ṙ = 0 there with a near-triple root: in double (ṙ = 0 exactly)
# its roots lie within ~1e-100 of t = 0, but the same initial numbers in long double carry ṙ ~ 1e-17, which the
# cube root spreads to crossings up to ~1e-8 after the start (measured: 2e-9 to 2.5e-8). 1e-6 takes them all as
# the initial point, so that the long-double reference driver and the engine agree on such orbits (the engine
# redoes an orbit on it when heyoka's root finding fails: hhscatter.integrate.engine).
T_INITIAL = 1e-6
# An orbit that starts on the section puts a root of the section event at its start (x p_x + y p_y = 0 there; the
# offset moves it to ~1e-300/ḟ(0), ḟ = d(x p_x + y p_y)/dt). Where ḟ(0) is small (r̈ ≈ 0 as well: the start is near
# an inflection of r) that root is nearly double, and heyoka (a) fails to isolate it now and then (the event
# is then ignored in the step; logged) and (b) deduces from ḟ ≈ 0 a cooldown after it that swallowed the first true
# crossing, often every later one, without a word. Such orbits (|ḟ(0)| ≤ OPEN_LATE_SLOPE |p|²) therefore start
# with their section event off: the clock opens it at T_INITIAL (opens_late; hhscatter.integrate.lanes).
OPEN_LATE_SLOPE = 1e-3
# Where the scene has no clock (snapshots, a window open to the end), such an orbit is redone on the reference
# driver with this fixed section cooldown instead of heyoka's deduced one (two ṙ = 0 roots closer than this are
# one crossing there). Everywhere else heyoka's deduced cooldowns stay: a fixed one trades merged grazing
# crossings for duplicated roots (docs: concepts/events).
SECTION_COOLDOWN = 1e-9
CLOCK_MARGIN = 1e-9  # the clock opens a window this much early and closes it this much late


#: the outcome rules an event can trigger (each a handler of :class:`hhscatter.integrate.lanes.LaneRules`)
RULES = ("escape", "closure", "far", "resc", "radius", "section", "clock")


@dataclass(frozen=True)
class EventSpec:
    """EventSpec(name, direction, expression, role, rule=name, index=None): one event of a scene, as data.

    ``direction``: +1 (upward roots only), −1 (downward) or 0 (both);
    ``expression``: callable (Symbols) -> heyoka expression whose root is the event;
    ``rule``: the outcome rule its root triggers (one of :data:`RULES`; the handler
    :meth:`hhscatter.integrate.lanes.LaneRules.handler` binds); ``index``: the rule's argument (the radius
    number of a follow radius), or None.
    """

    name: str
    direction: int
    expression: Callable
    role: str
    rule: str = ""
    index: int | None = None

    def __post_init__(self):
        if not self.rule:
            object.__setattr__(self, "rule", self.name)
        if self.rule not in RULES:
            raise ValueError(f"event {self.name!r}: rule must be one of {RULES}, got {self.rule!r}")


@dataclass(frozen=True)
class Layout:
    """Where a scene's extra state and parameters live in the integrator.

    ``clock``: index of the clock variable σ in the state (None: no clock);
    ``gate``: index of the section gate in the runtime parameters (None: no
    sections); ``gamma``: index of γ (None: conservative); ``clock_scale``: G;
    ``tangent``: index of the tangent vector's first component δx in the state (δx, δy, δp_x, δp_y; None: no
    tangent dynamics), carried at the norm ν e^Λ (:data:`TANGENT_NORM`, :func:`log_stretch`).
    """

    n_state: int
    clock: int | None
    gate: int | None
    gamma: int | None
    n_pars: int
    clock_scale: float
    tangent: int | None = None


class Symbols:
    """The heyoka expressions events are written in (built lazily: no heyoka at import).

    ``products``: V and H with their natural powers ≥ 3 written as products (:func:`_powers_as_products`), for the
    orbits that start where such a power's base is 0 (:func:`zero_power_start`)."""

    def __init__(self, scene, layout: Layout, products: bool = False):
        import heyoka as hy  # deferred: heyoka loads on first use

        (self.x, self.y, self.px, self.py), self.V, self.H = scene.model.expressions(hy)
        if products:
            self.V, self.H = _powers_as_products(self.V), _powers_as_products(self.H)
        self.r2 = self.x**2 + self.y**2
        self.clock = hy.make_vars("sigma") if layout.clock is not None else None
        self.gate = hy.par[layout.gate] if layout.gate is not None else None
        self.gamma = hy.par[layout.gamma] if layout.gamma is not None else None


_PRODUCTS = {}  # repr of an expression -> (its rewrite or None, the bases of its natural powers ≥ 3 as numpy functions)


def _powers_as_products(expr):
    """The heyoka expression ``expr`` with every power of a natural exponent n ≥ 3 written as a product of n
    factors (squares stay: heyoka's square has no such defect); ``expr`` itself if it has none.

    heyoka's Taylor recurrence of uⁿ divides by u at the start of the step: an event whose expression holds
    y**3 (Hénon–Heiles' H) has non-finite Taylor coefficients in a step that starts at y = 0 exactly (an
    initial condition on an axis), and heyoka then skips the event in that step without a word. The closure
    event (E = E_c) of such an orbit, crossed in its first step, was missed and the orbit ran on to t_max.

    >>> import heyoka as hy
    >>> x, y = hy.make_vars("x", "y")
    >>> print(_powers_as_products(x**2 * y - y**3 / 3.0))
    ((y * x**2.0000000000000000) - (0.33333333333333331 * (y * y * y)))
    >>> e = x**2 + y**2
    >>> _powers_as_products(e) is e
    True
    """
    rewritten = _rewrite_powers(expr)[0]
    return rewritten if rewritten is not None else expr


def _rewrite_powers(expr):
    """(:func:`_powers_as_products`' rewrite or None when ``expr`` has no natural power ≥ 3, the bases of those
    powers as numpy functions of (x, y, px, py)); cached by the expression's text."""
    key = repr(expr)
    if key not in _PRODUCTS:
        _PRODUCTS[key] = _rewrite_powers_uncached(expr)
    return _PRODUCTS[key]


def _rewrite_powers_uncached(expr):
    import heyoka as hy  # deferred: heyoka loads on first use
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    found = []

    def walk(e):
        if e.is_Pow and e.exp.is_Integer and int(e.exp) >= 3:
            found.append(e)
            b = walk(e.base)
            return sp.Mul(*([b] * int(e.exp)), evaluate=False)
        if e.args:
            return e.func(*[walk(a) for a in e.args], evaluate=False)
        return e

    rewritten = walk(hy.to_sympy(expr))
    if not found:
        return None, ()
    names = sp.symbols("x y px py")
    bases = tuple(sp.lambdify(names, b, "numpy") for b in {f.base for f in found})
    return hy.from_sympy(rewritten), bases


def zero_power_start(scene, ics) -> np.ndarray | None:
    """zero_power_start(plan, ics) -> bool array (n,), or None: the orbits of a dissipative scene that start where
    the base of a natural power ≥ 3 in H is 0 exactly (y = 0 for Hénon–Heiles' y³).

    heyoka skips the closure event (E = E_c) in such an orbit's first step (:func:`_powers_as_products`): these
    orbits are integrated with H written in products (``Symbols(products=True)``). None if there is none, or the
    scene has no closure event.

    >>> import numpy as np
    >>> from hhscatter.integrate.plan import plan_of
    >>> from hhscatter.scene.scene import Scene
    >>> s = plan_of(Scene(energy=0.17, n=2, gamma=0.01))
    >>> zero_power_start(s, np.array([[0.05, 0.0, 0.0, 0.58], [0.05, 0.01, 0.0, 0.58]])).tolist()
    [True, False]
    """
    if not (scene.gamma > 0 and scene.noise is None) or not len(ics):
        return None
    bases = scene.cached("power bases", lambda: _rewrite_powers(_hamiltonian(scene.model))[1])
    if not bases:
        return None
    x, y, px, py = np.asarray(ics, dtype=float).T
    zero = np.zeros(len(x), dtype=bool)
    for base in bases:
        zero |= np.broadcast_to(base(x, y, px, py), zero.shape) == 0
    return zero if zero.any() else None


def _hamiltonian(model):
    """H of ``model`` as a heyoka expression."""
    import heyoka as hy  # deferred: heyoka loads on first use

    return model.expressions(hy)[2]


def far_radius(scene) -> float:
    """far_radius(scene) -> r_far: the scene's, or max(10 r_s, 2 r_esc)."""
    if scene.r_far is not None:
        return float(scene.r_far)
    return max(10.0 * scene.model.saddle_radius, 2.0 * scene.r_esc)


def clock_targets(scene, censor: bool) -> tuple:
    """clock_targets(plan, censor) -> ((orbit time, action), ...): when the clock acts, in order.

    Actions: 'open' the section window (at t_from − CLOCK_MARGIN, a window
    that opens late could miss a crossing) and 'close' it (at t_to +
    CLOCK_MARGIN); the section rule itself checks the exact window. With
    ``censor`` (a scheduler that censors by the clock: the stream) it also
    'censors' at t_max: in orbit time, so a censored orbit's end state does not
    depend on the orbits before it in its lane (a propagation bound's rounding
    did).
    """
    w = scene.sections
    out = []
    if w is not None and w.t_from > 0:
        out.append((max(float(w.t_from) - CLOCK_MARGIN, 0.0), "open"))
    if w is not None and math.isfinite(w.t_to):
        out.append((float(w.t_to) + CLOCK_MARGIN, "close"))
    if censor:
        out.append((float(scene.t_max), "censor"))
    return tuple(sorted(out))


def follow_radii(scene) -> tuple:
    """follow_radii(scene) -> the radii whose crossings a follow scene records: its own and r_esc."""
    return tuple(sorted(set(scene.follow.radii) | {float(scene.r_esc)}))


def layout(scene) -> Layout:
    """layout(plan) -> Layout: state and parameter slots the plan's events need (from its ``clock_targets``)."""
    targets = scene.clock_targets
    clock = 4 if targets else None
    n_pars = 0
    gamma = gate = None
    if scene.gamma > 0 and scene.noise is None:  # with noise the drag is the Ornstein–Uhlenbeck step's
        gamma, n_pars = n_pars, n_pars + 1
    if scene.sections is not None:
        gate, n_pars = n_pars, n_pars + 1
    scale = max(1.0, max(t for t, _ in targets)) if targets else 1.0
    n_state = 5 if clock is not None else 4
    if not getattr(scene, "tangent", False):
        return Layout(n_state, clock, gate, gamma, n_pars, scale)
    return Layout(n_state + TANGENT_SLOTS, clock, gate, gamma, n_pars, scale, n_state)


#: state slots of the tangent dynamics: the tangent vector δq (δx, δy, δp_x, δp_y)
TANGENT_SLOTS = 4

#: ν = 2⁻⁹⁶⁰, the norm the tangent vector starts at: δq(0) = ν u(0). heyoka's step-size control takes the largest
#: state component and the largest Taylor coefficients over the whole state; the linear equation δq̇ = A δq has
#: the flow's own radius of convergence, so its coefficients stay ν e^Λ times the flow's and never set a step
#: while ν e^Λ ≪ 1 (Λ ≤ 600: ν e^Λ < 10⁻¹⁰). An orbit's steps, events and end are then those of the same scene
#: without the tangent dynamics, bit for bit: the stretches belong to the very orbits a run without them follows.
#: δq's Taylor coefficients stay normal doubles (ν ≈ 10⁻²⁸⁹); a power of two makes e^Λ = |δq|/ν exact.
TANGENT_NORM = 2.0**-960

#: the largest log-stretch Λ an orbit may accumulate with its steps still those of the flow alone. Beyond it
#: δq starts to enter the step control (the orbit is no longer guaranteed to be the one of the scene without the
#: tangent dynamics): such orbits are counted and warned of (:func:`stretch_beyond`, :class:`TangentStretchWarning`).
#: Near Λ ≈ 1374 ν e^Λ overflows a double: the integration stops there with a FloatingPointError that says so.
MAX_LOG_STRETCH = 600.0

#: the scale by which a tangent vector whose norm overflows a double is read (a power of two: exact)
_READ_SCALE = 2.0**-64


class TangentStretchWarning(RuntimeWarning):
    """Orbits whose log-stretch Λ passed :data:`MAX_LOG_STRETCH`: their Λ is kept, but their steps are no longer
    guaranteed to be those of the scene without the tangent dynamics."""


def stretch_beyond(log_stretch) -> int:
    """stretch_beyond(log_stretch) -> how many of the log-stretches Λ (array, any shape) exceed
    :data:`MAX_LOG_STRETCH` (600) or are not finite: the orbits whose steps the tangent vector may have set.

    >>> stretch_beyond([0.0, 599.9, 600.5, 1e400])   # 1e400: an overflowed Λ
    2
    """
    a = np.asarray(log_stretch, dtype=float)
    return int(np.count_nonzero(~(a <= MAX_LOG_STRETCH)))


def log_stretch(dx, dy, dpx, dpy) -> float:
    """log_stretch(δx, δy, δp_x, δp_y) -> Λ = ln(|δq|/ν), the log-stretch of a tangent vector started at the norm
    ν = :data:`TANGENT_NORM` (any float type; the result a float). Finite components give a finite Λ, even where
    |δq| itself would overflow a double (Λ up to ≈ 1375).

    >>> log_stretch(TANGENT_NORM, 0.0, 0.0, 0.0), round(log_stretch(0.0, 3 * TANGENT_NORM, 0.0, 4 * TANGENT_NORM), 12)
    (0.0, 1.609437912434)
    >>> big = 1.5e308   # |δq| = √2·1.5e308 overflows; Λ = ln(√2·1.5e308) + 960 ln 2
    >>> round(log_stretch(big, big, 0.0, 0.0) - (math.log(math.sqrt(2) * 1.5) + 308 * math.log(10) + 960 * math.log(2)), 9)
    0.0
    """
    r = math.hypot(float(dx), float(dy), float(dpx), float(dpy))
    if math.isinf(r):  # components finite, the norm beyond the largest double: read at a scale
        s = _READ_SCALE
        h = math.hypot(float(dx) * s, float(dy) * s, float(dpx) * s, float(dpy) * s)
        return math.log(h) - math.log(s) - math.log(TANGENT_NORM)
    return math.log(r / TANGENT_NORM)


def tangent_start(scene, ics) -> np.ndarray:
    """tangent_start(plan, ics) -> (n, 4): the initial unit tangent vector u(0) of each orbit of ``ics`` (n, 4).

    u(0) = (−F_y, F_x, −p_y, p_x)/|∇H| with F = −∇V the system's force and ∇H = (−F_x, −F_y, p_x, p_y): a unit
    vector orthogonal to ∇H (it lies in the energy shell's tangent space: H is unchanged to first order along
    it) and to the Hamiltonian flow J∇H = (p_x, p_y, F_x, F_y). It depends on the initial state alone (not on
    the chunk, the lane or the seed). Where ∇H = 0 (a rest point) u(0) = (1, 0, 0, 0).

    >>> import numpy as np
    >>> from hhscatter.integrate.plan import plan_of
    >>> from hhscatter.scene.scene import Scene
    >>> u = tangent_start(plan_of(Scene(energy=0.2, n=1, tangent=True)), np.array([[0.1, 0.0, 0.0, 0.6]]))
    >>> np.round(u, 6).tolist()   # F = (-0.1, -0.01): u ∝ (0.01, -0.1, -0.6, 0), |.| = √0.3701
    [[0.016438, -0.164377, -0.986261, 0.0]]
    """
    ics = np.asarray(ics, dtype=float).reshape(-1, 4)
    x, y, px, py = ics.T
    fx, fy = scene.model.force(x, y)
    u = np.column_stack([-np.asarray(fy, float) * np.ones_like(x), np.asarray(fx, float) * np.ones_like(x), -py, px])
    norm = np.sqrt(np.sum(u * u, axis=1))
    rest = ~(norm > 0)
    u[~rest] /= norm[~rest, None]
    u[rest] = (1.0, 0.0, 0.0, 0.0)
    return u


def scene_events(scene) -> tuple:
    """scene_events(plan) -> tuple[EventSpec, ...]: the events a plan needs, in callback order (from its
    ``far_radius``, ``follow_radii`` and ``clock_targets``).

    Only what the scene needs is compiled: the section event only for scenes
    with a section window (and switched off per lane outside it), the clock
    for windows that open late or close and for censoring in stream scenes
    (no snapshots), the follow radii only for
    follow scenes.
    """
    r_esc2 = scene.r_esc**2
    rf2 = scene.far_radius**2
    ec = scene.model.critical_energy
    ev = []
    if scene.gamma > 0 and scene.noise is None:
        ev.append(EventSpec("closure", -1, partial(_energy_minus, ec), "dissipative: E = E_c, settled or escaped"))
        ev.append(EventSpec("far", +1, partial(_far, rf2), "escaped orbit far away"))
        ev.append(EventSpec("resc", 0, partial(_radius, r_esc2), "last outward r_esc crossing"))
    elif scene.follow is None:
        ev.append(EventSpec("escape", +1, partial(_radius, r_esc2), "conservative escape"))
    else:
        # each root is declared once: two terminal events with the same root in one lane lose
        # one of them in batch mode (measured), so the r_esc radius is also the escape event
        ev.append(EventSpec("far", +1, partial(_far, rf2), "followed orbit far away"))
        for k, R in enumerate(scene.follow_radii):
            ev.append(
                EventSpec(
                    f"radius{k}",
                    0,
                    partial(_radius, R * R),
                    f"follow: crossing of r = {R:g}" + (" (outward: the escape)" if R == scene.r_esc else ""),
                    rule="radius",
                    index=k,
                )
            )
    if scene.sections is not None:
        ev.append(EventSpec("section", 0, _gated_section, "section ṙ = 0 (gated)"))
    if scene.clock_targets:
        ev.append(EventSpec("clock", -1, _clock, "orbit-time schedule"))
    return tuple(ev)


# the events' expressions: module-level functions (bound with functools.partial), so that a plan pickles and
# is handed to worker processes as it is


def _energy_minus(ec, s):
    return s.H - ec


def _far(rf2, s):
    return s.r2 / rf2 - 1.0


def _radius(R2, s):
    return s.r2 - R2


def _gated_section(s):
    return s.gate * (s.x * s.px + s.y * s.py - SECTION_OFFSET) + (1.0 - s.gate)


def _clock(s):
    return s.clock


def system(scene, lay: Layout):
    """system(scene, layout) -> heyoka ODE system: Hamilton's equations + drag (+ the clock) (+ the tangent
    dynamics, :func:`tangent_equations`)."""
    import heyoka as hy  # deferred: heyoka loads on first use

    sys = scene.model.equations(hy, hy.par[lay.gamma] if lay.gamma is not None else None)
    flow = list(sys)
    if lay.clock is not None:
        sys.append((hy.make_vars("sigma"), hy.expression(-1.0 / lay.clock_scale)))
    if lay.tangent is not None:
        sys.extend(tangent_equations(flow, hy))
    return sys


def tangent_equations(flow, hy) -> list:
    """tangent_equations(flow, hy) -> heyoka system of the tangent vector δq (the variational equation).

    ``flow``: [(q_i, f_i), ...], the flow's variables and right-hand sides (drag included); A_ij = ∂f_i/∂q_j
    (heyoka's ``diff``, any system). The variational equation δq̇ = A δq, linear: its solution is analytic
    wherever the flow's is (the same radius of convergence of its Taylor series, so the same steps serve both).
    Started at δq(0) = ν u(0) (:data:`TANGENT_NORM`), Λ(t) = ln(|δq(t)|/ν) (:func:`log_stretch`) is the
    log-stretch and Λ/t the finite-time Lyapunov exponent. The variables are named ``d_<q>``.

    >>> import heyoka as hy
    >>> x, p = hy.make_vars("x", "p")
    >>> [(str(v), str(f)) for v, f in tangent_equations([(x, p), (p, x)], hy)]   # the saddle ẋ = p, ṗ = x
    [('d_x', 'd_p'), ('d_p', 'd_x')]
    """
    qs = [q for q, _ in flow]
    ds = hy.make_vars(*(f"d_{q}" for q in qs))
    return [(d, hy.sum([hy.diff(f, q) * e for q, e in zip(qs, ds)])) for d, (_, f) in zip(ds, flow)]


#: the layout of Hamilton's equations alone (x, y, px, py: no clock, no parameters)
HAMILTON_ONLY = Layout(4, None, None, None, 0, 1.0)


def two_phase(scene) -> bool:
    """two_phase(scene) -> True if the section event is compiled only into an orbit's second phase.

    Scenes without snapshots whose section window opens late (t_from > 0):
    orbits run without the section event until the clock opens the window,
    then move to an integrator that has it (hhscatter.integrate.engine). Snapshot scenes
    switch the event off per lane instead (all lanes share one grid there).
    """
    return scene.sections is not None and scene.sections.t_from > 0 and not scene.snapshots


# -- outcome rules ---------------------------------------------------------------


def closure_rule(r2: float, r_s: float, last_out) -> int | None:
    """closure_rule(r², r_s, last_out) -> SETTLED, ESCAPED or None (carry on).

    At E = E_c: inside Ω (r ≤ r_s) the orbit can never leave: settled at this
    root. Outside, it is escaped at its last outward r_esc crossing; with no
    such crossing yet it is outside Ω below E_c, cannot come back, and the
    r_esc (then r_far) crossing ends it.
    """
    if r2 <= r_s * r_s:
        return SETTLED
    return ESCAPED if last_out is not None else None


def opens_late(scene, ics):
    """opens_late(scene, ics) -> bool array (n,), or None: the orbits whose section window opens at T_INITIAL.

    Those of a scene whose window is open from the start that start on the section (x p_x + y p_y = 0 to
    rounding) with |ḟ(0)| = |p|² + x F_x + y F_y| ≤ OPEN_LATE_SLOPE |p|² (F = −∇V, the system's force): near
    an inflection of r, where the section event's root at the start is nearly double. None if there is none.
    """
    w = scene.sections
    if w is None or w.t_from > 0 or not len(ics):
        return None
    x, y, px, py = np.asarray(ics, dtype=float).T
    on = np.abs(x * px + y * py) <= 4 * np.finfo(float).eps * (np.abs(x * px) + np.abs(y * py))
    fx, fy = scene.model.force(x, y)
    p2 = px * px + py * py
    late = on & (np.abs(p2 + x * fx + y * fy) <= OPEN_LATE_SLOPE * p2)
    return late if late.any() else None


def section_accepts(window, t: float, x: float, y: float, px: float, py: float, energy: float) -> bool:
    """section_accepts(window, t, x, y, px, py, E) -> bool: is this ṙ = 0 root a recorded section point?

    φ̇ > 0 (x p_y − y p_x > 0), orbit time in [t_from, t_to] and after the
    initial point, energy in [e_min, e_max].
    """
    return (
        x * py - y * px > 0
        and t >= T_INITIAL
        and window.t_from <= t <= window.t_to
        and window.e_min <= energy <= window.e_max
    )


__all__ = [
    "CENSORED",
    "ESCAPED",
    "OUTCOMES",
    "SETTLED",
    "STOPPED",
    "EventSpec",
    "HAMILTON_ONLY",
    "Layout",
    "RULES",
    "clock_targets",
    "follow_radii",
    "closure_rule",
    "far_radius",
    "opens_late",
    "layout",
    "scene_events",
    "two_phase",
    "section_accepts",
    "zero_power_start",
    "system",
    "log_stretch",
    "tangent_equations",
    "tangent_start",
    "MAX_LOG_STRETCH",
    "stretch_beyond",
    "TangentStretchWarning",
    "TANGENT_NORM",
    "TANGENT_SLOTS",
]
