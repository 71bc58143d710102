"""Publish: number formatting (``formatting``), numbers and readings in prose from the committed JSON (``numbers``,
``readings``), the studies report (``report``) and the figure backend (``figures``)."""
