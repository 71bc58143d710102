"""Progress of a long run: a tqdm bar in a terminal or notebook, plain lines otherwise, nothing when asked."""

from __future__ import annotations

import importlib.util
import sys
import time


class PlainProgress:
    """Progress for logs: a plain line on stderr at most every ``every`` seconds and at the end, no '\\r'."""

    def __init__(self, total, initial=0, desc="", every=10.0, file=None):
        self.total, self.n, self.desc, self.every = total, initial, desc, every
        self.file = file or sys.stderr
        self.t0 = self.last = time.perf_counter()

    def update(self, k):
        self.n += k
        now = time.perf_counter()
        if now - self.last >= self.every or self.n >= self.total:
            self.last = now
            print(
                f"{self.desc}: {self.n}/{self.total} orbits ({100 * self.n / max(self.total, 1):.0f} %), "
                f"{now - self.t0:.0f} s",
                file=self.file,
                flush=True,
            )

    def close(self):
        pass


def progress_bar(progress, total, initial, desc):
    """progress_bar(progress, total, initial, desc) -> object with update(n)/close(): tqdm, PlainProgress or silent.

    ``progress=True`` draws a tqdm bar only where one can be seen: on a terminal (stderr a TTY) or in a
    Jupyter kernel (a widget if ipywidgets is installed, else text); into a log file or a pipe it writes the
    plain lines of ``'plain'`` instead (no carriage returns). ``False``: silent, tqdm not even imported.
    """
    if progress == "plain" or (progress and not sys.stderr.isatty() and "ipykernel" not in sys.modules):
        return PlainProgress(total, initial, desc)
    if not progress:
        return _Silent()

    if sys.stderr.isatty() or importlib.util.find_spec("ipywidgets") is None:
        # a text bar (tqdm.auto would warn in a kernel without ipywidgets)
        from tqdm.std import tqdm  # deferred: tqdm loads on first use
    else:
        from tqdm.auto import tqdm  # deferred: tqdm loads on first use

    return tqdm(total=total, initial=initial, unit="orbit", unit_scale=True, desc=desc, smoothing=0.05)


class _Silent:
    def update(self, n=1):
        pass

    def close(self):
        pass
