"""Integrate: events as data (``events``) and the heyoka batch engine that decides outcomes at exact roots (``engine``).

Depends on :mod:`hhscatter.scene` and :mod:`hhscatter.model`.
"""
