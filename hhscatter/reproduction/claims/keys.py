"""Names of the raw runs of the claims (one per system, energy, drag and kind), and the energies of the section runs."""

from __future__ import annotations


def grid_key(label: str, r: float) -> str:
    """grid_key('contopoulos', 1.5) -> 'contopoulos_r1.500': the κ0(E) run at E = r·E_c."""
    return f"{label}_r{r:.3f}"


def alt_key(label: str, r: float, region: str) -> str:
    """alt_key('barbanis', 1.5, 'well') -> 'barbanis_well_r1.500': the κ0(E) run with the alternative ICs."""
    return f"{label}_{region}_r{r:.3f}"


def probe_key(label: str, r: float) -> str:
    """probe_key(label, r) -> '<label>_probe_r<r>': the probe-drag run at E = r·E_c."""
    return f"{label}_probe_r{r:.3f}"


def diss_key(label: str, gamma: float) -> str:
    """diss_key(label, γ) -> '<label>_g<γ:g>', e.g. 'barbanis_g0.01' (γ = 0: the conservative reference)."""
    return f"{label}_g{float(gamma):g}"


def cm_key(label: str, r: float) -> str:
    """cm_key('barbanis', 2.6) -> 'barbanis_cm_r2.600': the conservative run recording every section crossing."""
    return f"{label}_cm_r{r:.3f}"


def sec_key(label: str, gamma: float) -> str:
    """sec_key(label, γ) -> '<label>_sec_g<γ>': the dissipative run recording the section crossings around t*."""
    return f"{label}_sec_g{float(gamma):g}"


def cm_ratios(p) -> list:
    """The energies (E/E_c) of the section-recording conservative runs: cm_ratios and e0_ratio (claim 5's μ_c^{E0})."""
    return sorted({*map(float, p.cm_ratios), float(p.e0_ratio)})


def ev_key(label: str, ics: str, r: float) -> str:
    """ev_key('barbanis', 'disk', 1.5) -> 'barbanis_ev_disk_r1.500': the long conservative run (indicator window)."""
    return f"{label}_ev_{ics}_r{r:.3f}"


def ps_key(label: str, r: float) -> str:
    """ps_key(label, r) -> '<label>_ps_r<r>': the run recording every section crossing (Poincaré sections)."""
    return f"{label}_ps_r{r:.3f}"


def resc_key(label: str, r_esc, kind: str) -> str:
    """resc_key('henon_heiles', 1.03, 'probe_r1.800') -> 'henon_heiles_resc1.03_probe_r1.800' (None: the default)."""
    return f"{label}_resc{'default' if r_esc is None else f'{r_esc:g}'}_{kind}"


def map_key(label: str, r: float) -> str:
    """map_key('barbanis', 5.0) -> 'barbanis_map_r5.000': the validity map's κ0 run at an energy off the claims' grid
    (the claims' κ0 scene)."""
    return f"{label}_map_r{r:.3f}"


def map_ratios(p) -> list:
    """The validity map's energies (E/E_c of ev_ratios) off the claims' grid (ratios): each gets a κ0 run of its own
    with the claims' scene (:func:`map_key`).

    >>> from types import SimpleNamespace as NS
    >>> map_ratios(NS(ratios=[1.05, 1.5, 2.6], ev_ratios=[1.05, 1.7, 2.6, 5.0]))
    [1.7, 5.0]
    """
    return [float(r) for r in p.ev_ratios if not any(abs(float(r) - float(x)) < 1e-9 for x in p.ratios)]


def lab_key(label: str, r: float) -> str:
    """lab_key('barbanis', 1.05) -> 'barbanis_ev_disk_r1.050_label': the labelled set of the disk ensemble at
    E = r·E_c (its band's orbits and a sample either side, run again with the tangent dynamics to a longer time)."""
    return f"{ev_key(label, 'disk', r)}_label"
