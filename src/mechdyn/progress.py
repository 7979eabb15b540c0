"""Progress on stderr for long runs: a tqdm bar over simulated time (:class:`Progress`)
and a line naming a stage still running (:func:`stage`).

Every one takes a ``progress`` mode: True shows it at once, False never, None (the
default of the commands) once the work has taken longer than :data:`PROGRESS_AFTER`
seconds of wall time, so quick runs stay silent.
"""

from __future__ import annotations

import sys
import threading
import time
from contextlib import contextmanager

__all__ = ["Progress", "PROGRESS_AFTER", "stage"]

#: runs that take longer than this (s of wall time) show a progress bar (progress=None)
PROGRESS_AFTER = 2.0


def _delay(mode) -> float:
    return 0.0 if mode is True else PROGRESS_AFTER


class Progress:
    """A tqdm bar over simulated time, shown at once (True), never (False) or once
    the run has taken longer than PROGRESS_AFTER seconds (None; tqdm's ``delay``)."""

    def __init__(self, mode, t0, t_end):
        self.shown = t0
        self.bar = None
        if mode is True or mode is None:
            from tqdm import tqdm

            self.bar = tqdm(total=t_end - t0, unit="s", file=sys.stderr, desc="simulate",
                            delay=_delay(mode),
                            bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s "
                            "[{elapsed}<{remaining}]")

    def update(self, t):
        if self.bar is not None:
            self.bar.update(t - self.shown)
        self.shown = t

    def close(self):
        if self.bar is not None:
            self.bar.close()


@contextmanager
def stage(what: str, progress: bool | None = None, *, done: str | None = None,
          after: float | None = None, since: float | None = None):
    """Say on stderr ``"<what> ..."`` once the block has run longer than
    :data:`PROGRESS_AFTER` seconds (at once for True, never for False), and how long it
    took when it ends; a quick block says nothing.

    Parameters
    ----------
    what : str
        The stage, e.g. ``"report: kinetostatics over 361 positions"``.
    progress : bool or None
        Say it at once (True), never (False) or once the block has run longer than
        :data:`PROGRESS_AFTER` seconds (None).
    done : str, optional
        The closing line, ``{:.1f}`` taking the seconds (default ``"<what>: done in
        {:.1f} s"``).
    after : float, optional
        Seconds before the line for ``progress=None`` (default :data:`PROGRESS_AFTER`).
    since : float, optional
        The ``time.perf_counter()`` those seconds count from (default now): the stages
        of one run share the start of the run, so the stage running once the run has
        taken 2 s is named.

    Examples
    --------
    >>> with stage("report: nothing much", progress=False):
    ...     pass
    """
    if progress is False:
        yield
        return
    t0 = time.perf_counter()
    spent = 0.0 if since is None else t0 - since
    said = []

    def announce():
        said.append(True)
        print(f"{what} ...", file=sys.stderr, flush=True)

    wait = (_delay(progress) if after is None or progress is True else after) - spent
    timer = threading.Timer(wait, announce)
    timer.daemon = True
    if wait > 0:
        timer.start()
    else:  # at once, before the block can end
        announce()
    try:
        yield
    finally:
        timer.cancel()
        if timer.is_alive():
            timer.join()
        if said:
            closing = done if done is not None else what + ": done in {:.1f} s"
            print(closing.format(time.perf_counter() - t0), file=sys.stderr, flush=True)
