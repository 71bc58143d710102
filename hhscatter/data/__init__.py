"""Store and read the tables: the Parquet contract (``schema``), part-file writers (``write``), verified readers
(``read``) and the file store (``store``: local paths or fsspec URLs, atomic writes, the run lock).

Depends on :mod:`hhscatter.scene` and :mod:`hhscatter.model`; never on the analysis.
"""
