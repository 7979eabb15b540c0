"""The pieces of a load table, held through a step of the compiled DOP853 loop.

A table load (:class:`mechdyn.mechanism.load.Table`, a torque-speed curve) is linear
between its points: at a point its slope changes, and where it ends with an ``outside``
value (or a periodic table starts again) its value jumps.  A Runge-Kutta step whose
stages fall on both sides of such a point integrates a function that is not smooth:
the step is not of the method's order and its error estimate, which assumes a smooth
solution, can pass it with an error far above the tolerance (the press cycle at rtol
1e-10: a rocker rate wrong by 1.6e-5 rad/s after one step across the spring table's
knee) or reject it again and again.  An error that falls on one stage alone is nearly
invisible to the estimate, so ending the step *near* the point is not enough.

The compiled loop therefore *holds* the piece of every such table through a step (its
stages extend the piece linearly past its ends, so that every stage sees one smooth
function), and looks at the table variables at the end of each accepted step: where one
has left its piece, the step is taken again, shortened to end where the variable meets
the piece's end (linear in the variable between the step's ends; again until the point
lies within :data:`ETA` of the step's end), and the next piece is held from there.  The
error of the part past the point then falls with the square of its length.  A shortened
step that lands short of the point (by more than ETA of the first step's travel past it)
is followed by steps that aim at it by regula falsi with Illinois' rule over the bracket
of its time, not from past it again.

A *region* of a table of n points is ``g`` in 0..n: 0 below the first point, g between
points g - 1 and g, n above the last point; a periodic table also has its period count
``kp`` (the variable minus ``kp`` periods lies in ``[x0, x0 + period)``).  Only tables
with sharp points (:func:`sharp_breakpoints`) are held: a smooth curve tabulated finely
is left to the step control.
"""

from __future__ import annotations

import numpy as np

from .rows_numba import njit

__all__ = ["sharp_breakpoints", "region_of", "region_bounds", "region_value", "ETA", "SHARP"]

#: the part of a step past a table's point that is accepted without taking it again
ETA = 1e-6
#: a point is sharp where the table's jump there, or its change of slope times the shorter
#: of the two intervals beside it, exceeds this fraction of its largest value
SHARP = 1e-2


def sharp_breakpoints(xs, ys, outside=None, period=None) -> np.ndarray:
    """The points of a table at which its value jumps or its slope changes sharply.

    Parameters
    ----------
    xs, ys : array_like, shape (n,)
        The table's points (non-decreasing ``xs``).
    outside : float or None
        The value outside ``[xs[0], xs[-1]]`` (None: the end values are held).
    period : float or None
        The period of a periodic table (on ``(xs[-1], xs[0] + period)`` it takes the end
        value or ``outside``, and at ``xs[0] + period`` it starts again).

    Returns
    -------
    ndarray, shape (k,)
        The sharp points (see :data:`SHARP`), in the units of ``xs``.

    Examples
    --------
    >>> sharp_breakpoints([0.0, 1.0, 2.0], [0.0, 10.0, 10.0]).tolist()
    [0.0, 1.0]
    >>> sharp_breakpoints([0.0, 1.0], [5.0, 5.0], outside=0.0).tolist()
    [0.0, 1.0]
    """
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    n = xs.size
    span = max(np.max(np.abs(ys)) if n else 0.0, 0.0 if outside is None else abs(outside))
    if n == 0 or span == 0.0:
        return np.zeros(0)
    dx = np.diff(xs)
    slope = np.divide(np.diff(ys), dx, out=np.zeros(n - 1), where=dx > 0)
    before = ys[-1] if outside is None and period is not None else outside
    sharp = []
    for i in range(n):
        vl = ys[i] if i > 0 else (ys[0] if before is None else before)
        vr = ys[i] if i < n - 1 or outside is None else outside
        sl = slope[i - 1] if i > 0 else 0.0
        sr = slope[i] if i < n - 1 else 0.0
        widths = [w for w in (dx[i - 1] if i > 0 else 0.0, dx[i] if i < n - 1 else 0.0)
                  if w > 0]
        jump = abs(vr - vl) + (abs(ys[i] - ys[i - 1]) if i > 0 and dx[i - 1] == 0 else 0.0)
        bend = abs(sr - sl) * min(widths) if widths else 0.0
        if max(jump, bend) > SHARP * span:
            sharp.append(xs[i])
    return np.unique(np.array(sharp, float))


@njit
def region_of(xs, n, per, s, direction):
    """``(g, kp)``: the region of the variable ``s`` (see the module); at a point
    exactly, the region on the side ``direction`` (> 0: above, else below).  ``per`` is
    the period, or 0 for a table that is not periodic."""
    kp = 0.0
    u = s
    if per > 0.0:
        kp = np.floor((s - xs[0]) / per)
        u = s - kp * per
        if u >= xs[0] + per:  # (rounding)
            kp += 1.0
            u -= per
        if u < xs[0] or (u == xs[0] and direction <= 0.0):  # below the start: last piece
            kp -= 1.0
            u += per
    g = 0
    for i in range(n):
        if xs[i] < u or (xs[i] == u and direction > 0.0):
            g = i + 1
    return g, kp


@njit
def region_bounds(xs, n, per, g, kp):
    """``(lo, hi)``: the ends of region ``g`` of period ``kp`` in the variable."""
    lo = -np.inf if g == 0 else xs[g - 1]
    hi = np.inf if g == n else xs[g]
    if per > 0.0:
        if g == 0:
            lo = xs[n - 1] - per
        if g == n:
            hi = xs[0] + per
        lo += kp * per
        hi += kp * per
    return lo, hi


@njit
def region_value(xs, ys, n, per, g, kp, s, has_out, outside):
    """The table's value at ``s`` on region ``g`` of period ``kp``, its piece extended
    linearly past the region's ends (constant on the end regions)."""
    if g == 0:
        if has_out:
            return outside
        return ys[n - 1] if per > 0.0 else ys[0]
    if g == n:
        return outside if has_out else ys[n - 1]
    dx = xs[g] - xs[g - 1]
    if dx == 0.0:
        return ys[g - 1]
    u = s - kp * per
    return ys[g - 1] + (u - xs[g - 1]) * (ys[g] - ys[g - 1]) / dx
