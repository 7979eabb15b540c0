"""A progress bar over simulated time for long runs (tqdm, on stderr)."""

from __future__ import annotations

import sys

__all__ = ["Progress", "PROGRESS_AFTER"]

#: runs that take longer than this (s of wall time) show a progress bar (progress=None)
PROGRESS_AFTER = 2.0


class Progress:
    """A tqdm bar over simulated time, shown at once (True), never (False) or once
    the run has taken longer than PROGRESS_AFTER seconds (None; tqdm's ``delay``)."""

    def __init__(self, mode, t0, t_end):
        self.shown = t0
        self.bar = None
        if mode is True or mode is None:
            from tqdm import tqdm

            self.bar = tqdm(total=t_end - t0, unit="s", file=sys.stderr, desc="simulate",
                            delay=0.0 if mode else PROGRESS_AFTER,
                            bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s "
                            "[{elapsed}<{remaining}]")

    def update(self, t):
        if self.bar is not None:
            self.bar.update(t - self.shown)
        self.shown = t

    def close(self):
        if self.bar is not None:
            self.bar.close()
