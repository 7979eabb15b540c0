"""A progress bar over simulated time for long runs (tqdm, on stderr)."""

from __future__ import annotations

import sys
import time

__all__ = ["Progress", "PROGRESS_AFTER"]

#: runs predicted longer than this (s of wall time) show a progress bar (progress=None)
PROGRESS_AFTER = 2.0


class Progress:
    """A tqdm bar over simulated time, shown at once (True), never (False) or once
    the run has taken longer than PROGRESS_AFTER seconds (None)."""

    def __init__(self, mode, t0, t_end):
        self.mode, self.t0, self.t_end = mode, t0, t_end
        self.bar = None
        self.start = time.perf_counter()
        self.shown = t0
        if mode is True:
            self._open()

    def _open(self):
        try:
            from tqdm import tqdm
        except ImportError:  # pragma: no cover - tqdm is a dependency
            self.mode = False
            return
        self.bar = tqdm(total=self.t_end - self.t0, unit="s", file=sys.stderr,
                        desc="simulate", bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s "
                        "[{elapsed}<{remaining}]")

    def update(self, t):
        if self.bar is None and self.mode is None and \
                time.perf_counter() - self.start > PROGRESS_AFTER:
            self._open()
            if self.bar is not None:
                self.bar.update(self.shown - self.t0)
        if self.bar is not None:
            self.bar.update(t - self.shown)
        self.shown = t

    def close(self):
        if self.bar is not None:
            self.bar.close()
