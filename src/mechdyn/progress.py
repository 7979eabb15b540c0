"""Progress on stderr for long runs: a tqdm bar over simulated time (:class:`Progress`),
over the items of a loop (:func:`bar`), and a line naming a stage still running
(:func:`stage`).

Every one takes a ``progress`` mode: True shows it at once, False never, None (the
default of the commands) once the work has taken longer than :data:`PROGRESS_AFTER`
seconds of wall time, so quick runs stay silent.
"""

from __future__ import annotations

import sys
import threading
import time
from contextlib import contextmanager

__all__ = ["Progress", "PROGRESS_AFTER", "bar", "stage"]

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


def bar(iterable=None, *, total: int | None = None, desc: str = "", unit: str = "it",
        progress: bool | None = None):
    """A tqdm bar on stderr over ``iterable`` (or ``total`` items, advanced by ``update``).

    Parameters
    ----------
    iterable : iterable, optional
        The items; the bar yields them.
    total : int, optional
        Number of items (default ``len(iterable)``).
    desc, unit : str
        The label before the bar and the name of one item.
    progress : bool or None
        Show the bar at once (True), never (False) or once the loop has taken longer
        than :data:`PROGRESS_AFTER` seconds (None).

    Returns
    -------
    tqdm
        The bar (disabled when ``progress`` is False); close it, or exhaust it.

    Examples
    --------
    >>> sum(bar(range(4), desc="adding", progress=False))
    6
    """
    from tqdm import tqdm

    return tqdm(iterable, total=total, desc=desc, unit=unit, file=sys.stderr,
                delay=_delay(progress), disable=progress is False, leave=False)


@contextmanager
def stage(what: str, progress: bool | None = None):
    """Say on stderr ``"<what> ..."`` once the block has run longer than
    :data:`PROGRESS_AFTER` seconds (at once for True, never for False), and how long it
    took when it ends; a quick block says nothing.

    Parameters
    ----------
    what : str
        The stage, e.g. ``"report: kinetostatics over 361 positions"``.
    progress : bool or None
        As for :func:`bar`.

    Examples
    --------
    >>> with stage("report: nothing much", progress=False):
    ...     pass
    """
    if progress is False:
        yield
        return
    t0 = time.perf_counter()
    said = []

    def announce():
        said.append(True)
        print(f"{what} ...", file=sys.stderr, flush=True)

    timer = threading.Timer(_delay(progress), announce)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
        timer.join()
        if said:
            print(f"{what}: done in {time.perf_counter() - t0:.1f} s", file=sys.stderr,
                  flush=True)
