"""Entry points of the notebook API that start from a run directory (the analysis layer itself reads no files).

:func:`kappa_cmeasure` reads a run's lifetimes, its sections and the section window and ``t_max`` it was
recorded with (its ``scene.json``), and hands them to :func:`hhscatter.analysis.frames.kappa_cmeasure`.
"""
from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # annotations only
    from .analysis.frames import CMeasureRates

__all__ = ["kappa_cmeasure", "run_scene"]


def run_scene(run) -> dict:
    """run_scene(run) -> the scene dict a run directory was written with (``scene.json``; infinities decoded).

    Raises ValueError if ``run`` holds no ``scene.json`` (not a run of :func:`hhscatter.simulate`).
    """
    from .runner import SCENE_FILE, _decode
    from .store import Store

    store = Store(run)
    if not store.exists(SCENE_FILE):
        raise ValueError(f"{run}: no {SCENE_FILE}: not a run directory written by hhscatter.simulate")
    return _decode(json.loads(store.read_text(SCENE_FILE))["scene"])


def kappa_cmeasure(run: str | os.PathLike[str], **kwargs: Any) -> CMeasureRates:
    """κ from the c-measure of a run's section crossings, per conservative grid point, beside κ from P(t).

    Parameters
    ----------
    run : str or Path
        A run directory of :func:`hhscatter.simulate` whose scene recorded every section crossing
        (``sections=SectionWindow(t_from=…, t_to=…)``, no energy filter, not ``first_only``).
    **kwargs
        ``t_from``, ``t_to``, ``rec_efolds``, ``margin``, ``n_boot``, ``seed`` of
        :func:`hhscatter.analysis.frames.kappa_cmeasure`, which does the work (its docstring has the method).

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
    from .analysis.frames import kappa_cmeasure as from_frames
    from .tables import read_lifetimes, read_sections

    scene = run_scene(run)
    if not scene.get("sections"):
        raise ValueError(f"{run}: the run recorded no sections; simulate with sections=SectionWindow(t_from=…, "
                         "t_to=…) (every crossing, no energy filter)")
    return from_frames(read_lifetimes(run), read_sections(run), window=scene["sections"],
                       t_max=float(scene["t_max"]), **kwargs)
