"""Warnings of the libraries an analysis calls (numpy, scipy), captured and counted instead of printed or dropped.

A fit run a thousand times in a bootstrap may warn on a few replicates (an overflow in ``exp``, a covariance that
cannot be estimated); the analysis already handles those replicates (a NaN, a failed fit it counts), so the warning
is not shown, but it is not lost either: :func:`counted` records each warning raised in its block under the name of
the place that called it, and :func:`warning_counts` returns the tally. An analysis writes the tally into
its numbers JSON (key ``library_warnings``) and prints its total.

Examples
--------
>>> import warnings
>>> reset_warning_counts()
>>> with counted("example.fit"):
...     warnings.warn("covariance could not be estimated", RuntimeWarning)
...     warnings.warn("covariance could not be estimated", RuntimeWarning)
>>> warning_counts()
[{'where': 'example.fit', 'category': 'RuntimeWarning', 'message': 'covariance could not be estimated', 'count': 2}]
>>> reset_warning_counts()

A message that names a file keeps the file's name, not the folders it lies in (the tally goes into a committed
JSON; where the machine keeps its runs is not a result):

>>> with counted("example.read"):
...     warnings.warn("nothing matched in the table of /data/me/runs/out/raw/E0.30_r1.5 (its points: E = 0.3)")
>>> warning_counts()[0]["message"]
'nothing matched in the table of E0.30_r1.5 (its points: E = 0.3)'
>>> reset_warning_counts()
"""

from __future__ import annotations

import re
import warnings
from collections import Counter
from contextlib import contextmanager

_COUNTS: Counter = Counter()
_MESSAGE_CHARS = 200  # a message is kept to its first line, at most this many characters
# an absolute path (POSIX or Windows) in a message: the folders before its last component are dropped
_FOLDERS = re.compile(r"(?:(?<![\w.])/|\b[A-Za-z]:[\\/])(?:[^\s/\\'\"()]+[/\\])+(?=[^\s/\\'\"()])")


def _without_folders(text: str) -> str:
    """``text`` with every absolute path reduced to its last component."""
    return _FOLDERS.sub("", text)


@contextmanager
def counted(where: str):
    """counted(where) -> context manager: warnings raised in the block are recorded under ``where`` (the place in
    the analysis, e.g. ``"survival.kappa_energy.bootstrap"``), not shown; the count of each (category, message)
    goes to the process's tally (:func:`warning_counts`). Errors pass through unchanged.

    Examples
    --------
    >>> import numpy as np
    >>> reset_warning_counts()
    >>> with counted("example.ratio"):
    ...     ratio = np.float64(1.0) / 0.0        # numpy warns (divide by zero), the block goes on
    >>> float(ratio), [(r["where"], r["category"], r["count"]) for r in warning_counts()]
    (inf, [('example.ratio', 'RuntimeWarning', 1)])
    >>> reset_warning_counts()
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")  # every occurrence, not the first per place: they are counted
        try:
            yield
        finally:
            for w in caught:
                text = _without_folders(str(w.message).strip())
                _COUNTS[(where, w.category.__name__, text.splitlines()[0][:_MESSAGE_CHARS] if text else "")] += 1


def warning_counts() -> list[dict]:
    """warning_counts() -> [{where, category, message, count}], one record per distinct warning counted by
    :func:`counted` since the last :func:`reset_warning_counts`, sorted by place, then by count (largest first).

    Examples
    --------
    >>> import warnings
    >>> reset_warning_counts()
    >>> for where, n in (("b.fit", 1), ("a.fit", 3)):
    ...     for _ in range(n):
    ...         with counted(where):
    ...             warnings.warn("overflow in exp", RuntimeWarning)
    >>> [(r["where"], r["count"]) for r in warning_counts()]     # one record per place and message, by place
    [('a.fit', 3), ('b.fit', 1)]
    >>> reset_warning_counts()
    """
    recs = [{"where": w, "category": c, "message": m, "count": int(n)} for (w, c, m), n in _COUNTS.items()]
    return sorted(recs, key=lambda r: (r["where"], -r["count"], r["category"], r["message"]))


def reset_warning_counts() -> None:
    """reset_warning_counts() -> None: empty the tally (before an analysis whose warnings are to be counted alone).

    Examples
    --------
    >>> import warnings
    >>> with counted("example.fit"):
    ...     warnings.warn("covariance could not be estimated")
    >>> len(warning_counts()) > 0
    True
    >>> reset_warning_counts()
    >>> warning_counts()
    []
    """
    _COUNTS.clear()
