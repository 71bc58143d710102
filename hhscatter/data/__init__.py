"""Store and read the tables: Parquet schemas, provenance, writers, verified readers (``tables``) and the file store (``store``).

Depends on :mod:`hhscatter.scene` and :mod:`hhscatter.model`; never on the analysis.
"""
