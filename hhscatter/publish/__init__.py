"""Publish: number formatting (``formatting``), the studies report (``report``) and the figure backend (``figures``)."""
