"""Run a scene or grid: planning, chunks, resume, progress, the process-pool and Dask backends (``runner``, ``dask_backend``).

Depends on :mod:`hhscatter.integrate`, :mod:`hhscatter.data` and :mod:`hhscatter.scene`.
"""
