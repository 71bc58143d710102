"""heyoka's log, captured: event-detection failures counted, every other line passed on.

heyoka writes its warnings through its C++ logger (spdlog) straight to the process's standard output (file
descriptor 1), out of reach of Python's ``warnings`` and ``logging``. One warning matters to the engine: when the
polynomial root finding of an event fails inside a step ("polynomial root finding during event detection failed
due to too many iterations", or "... returned a nonzero errno ..."), heyoka *ignores that event in that step*
and goes on. An escape, a settling or a section crossing can then be missed. :func:`capture` redirects
descriptor 1 into a temporary file while a block runs, counts those lines (:attr:`Log.event_failures`) and writes
every other line back to the real standard output, so nothing heyoka says is lost.

The redirection is process-wide: captures are serialised by a lock and nest (an inner capture adds its count to
the outer one's and passes its other lines on to it).

Example (lines that are not heyoka's pass through and count no failure; the count is checked on integrations
that provoke real event failures)::

>>> with capture() as log:
...     print("not heyoka's")
not heyoka's
>>> log.event_failures
0
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import threading

#: the start of heyoka's warnings that an event's root finding failed in a step (the event is then ignored)
EVENT_FAILURE = "polynomial root finding during event detection"

_FD = 1  # heyoka's logger writes to standard output
_LOCK = threading.RLock()
_ACTIVE = []  # the captures in progress in this process, innermost last


class Log:
    """What heyoka logged during a :func:`capture` block."""

    def __init__(self):
        self.event_failures = 0  # lines that report an event's root finding failed (the event was ignored)
        self.lines = []  # those lines, as heyoka wrote them

    def _take(self, text: str) -> str:
        """Count the event-failure lines of ``text``; return the other lines."""
        rest = []
        for line in text.splitlines(keepends=True):
            if EVENT_FAILURE in line:
                self.event_failures += 1
                self.lines.append(line.rstrip("\n"))
            else:
                rest.append(line)
        return "".join(rest)


def _read_from(fd: int, start: int) -> str:
    """The text written to ``fd`` (a regular file) from byte ``start`` on."""
    end = os.lseek(fd, 0, os.SEEK_END)
    return os.pread(fd, end - start, start).decode("utf-8", errors="replace") if end > start else ""


@contextlib.contextmanager
def capture():
    """capture() -> context manager yielding a :class:`Log`: heyoka's log while the block runs.

    Standard output (descriptor 1, where heyoka logs) goes to a temporary file for the block; on exit the
    event-failure lines are counted into the Log and every other line is written back to standard output. A
    capture inside another counts the lines of its own block; the outer one counts them too and passes the
    others on.
    """
    with _LOCK:
        log = Log()
        sys.stdout.flush()
        if _ACTIVE:  # nested: read this block's part of the outer capture's file
            fd = _ACTIVE[-1]
            start = os.lseek(fd, 0, os.SEEK_END)
            try:
                yield log
            finally:
                sys.stdout.flush()
                log._take(_read_from(fd, start))
            return
        saved = os.dup(_FD)
        tmp = tempfile.TemporaryFile(mode="w+b")
        try:
            os.dup2(tmp.fileno(), _FD)
            _ACTIVE.append(tmp.fileno())
            try:
                yield log
            finally:
                _ACTIVE.pop()
                sys.stdout.flush()
                os.dup2(saved, _FD)
                rest = log._take(_read_from(tmp.fileno(), 0))
                if rest:
                    sys.stdout.write(rest)
                    sys.stdout.flush()
        finally:
            os.close(saved)
            tmp.close()
