"""Define what to compute: the scene (one ensemble), its file schema, grids over (E0, γ) and initial conditions.

Depends on :mod:`hhscatter.model` only. ``scene`` (Scene, SectionWindow), ``schema`` (the validated scene, grid
and study files), ``grid`` (Grid over E0 and γ), ``ics`` (initial conditions of a scene).
"""
