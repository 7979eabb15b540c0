"""The loop's side of the held table pieces (:mod:`mechdyn.kernels.table_regions`): the
table variables of an evaluation, the pieces held, where a step leaves them, and what
becomes of the step then.

Used by :func:`mechdyn.kernels.dop853_numba.run`; the functions read the held tables'
records (section ``S_LOCK`` of the packed loads, :mod:`mechdyn.kernels.loads_numba`) and
the pieces held (``[region + 1, period count]`` per table, in the work array,
:func:`mechdyn.kernels.lagrange_numba.held_pieces`); :func:`again`, :func:`shortened` and
:func:`switch_at` decide on a step from where it left them, and keep the bracket of the
time of a point aimed at (see :func:`aim`).
"""

from __future__ import annotations

import numpy as np

from .lagrange_numba import D_NI, D_NQ, D_NV, table_inputs
from .loads_numba import H_FOFF, H_IOFF, H_NB, H_NTAB, IR_LOCK, S_LOCK, S_TAB
from .rows_numba import njit
from .table_regions import ETA, region_bounds, region_of

__all__ = ["table_vars", "hold", "left", "cut_back", "aim", "crossed", "again", "shortened",
           "switch_at", "ATTEMPTS", "KEEP", "BACK_TO_STAGE", "NEXT_PIECE", "UP_TO_POINT"]

#: attempts of a step taken again up to a table's point, at most
ATTEMPTS = 8
#: what becomes of a step at whose end a table variable has left its piece (:func:`again`)
KEEP, BACK_TO_STAGE, NEXT_PIECE, UP_TO_POINT = range(4)


@njit
def _table(ip, fp, j):
    """``(xs, n, period)`` of held table ``j`` (period 0: not periodic)."""
    o = ip[H_IOFF + S_LOCK] + IR_LOCK * j
    tab0 = ip[H_FOFF + S_TAB] + ip[o + 2]
    n = ip[o + 3]
    per = fp[tab0 + 2 * n] if ip[o + 4] & 2 else 0.0
    return fp[tab0:tab0 + n], n, per


@njit
def table_vars(t, ip, fp, dims, sc, out):
    """The variables of the held tables at the last evaluation, into ``out``."""
    q, qdot, varv = table_inputs(sc, 3 * ip[H_NB], dims[D_NI], dims[D_NQ], dims[D_NV])
    o = ip[H_IOFF + S_LOCK]
    for j in range(ip[H_NTAB]):
        kind, idx = ip[o + IR_LOCK * j], ip[o + IR_LOCK * j + 1]
        out[j] = t if kind == 0 else (q[idx] if kind == 1 else (
            qdot[idx] if kind == 2 else varv[idx]))


@njit
def _slack(xs, n, per, c):
    """How far past an end ``c`` of its piece a variable may lie and still count as on it
    (round-off: a ram held at a stop that is also a table's point must not flip between
    the two pieces there)."""
    return 1e-12 * (abs(c) + xs[n - 1] - xs[0] + per) if abs(c) < np.inf else 0.0


@njit
def hold(ip, fp, s, towards, locks, only_left, only=-1):
    """Hold the piece of each table at its variable ``s`` (at a point: the piece on the
    side of ``towards``); with ``only_left``, hold instead the piece next to the one held
    now, past the end that the variable has crossed on its way to ``towards``, of each
    table whose variable there has left the piece held now (of table ``only`` alone
    where it is not -1)."""
    for j in range(ip[H_NTAB]):
        if only >= 0 and j != only:
            continue
        xs, n, per = _table(ip, fp, j)
        if not only_left:
            g, kp = region_of(xs, n, per, s[j], towards[j] - s[j])
        else:
            g, kp = int(locks[2 * j]) - 1, locks[2 * j + 1]
            lo, hi = region_bounds(xs, n, per, g, kp)
            if towards[j] > hi + _slack(xs, n, per, hi):
                g += 1
                if g > n:  # (periodic: on into the next period; else held above)
                    g, kp = (1, kp + 1.0) if per > 0.0 else (n, kp)
            elif towards[j] < lo - _slack(xs, n, per, lo):
                g -= 1
                if g < 1 and per > 0.0:
                    g, kp = n, kp - 1.0
                g = max(g, 0)
        locks[2 * j], locks[2 * j + 1] = g + 1.0, kp


@njit
def left(ip, fp, old, new, locks):
    """``(theta, j, c)``: the smallest fraction ``theta`` of a step (in [0, 1], linear in
    the variable between its ends ``old`` and ``new``) at which a table variable leaves
    its held piece, the table ``j`` and the end ``c`` of its piece; theta 2.0 where none
    does."""
    best, jb, cb = 2.0, -1, 0.0
    for j in range(ip[H_NTAB]):
        xs, n, per = _table(ip, fp, j)
        lo, hi = region_bounds(xs, n, per, int(locks[2 * j]) - 1, locks[2 * j + 1])
        a, b = old[j], new[j]
        if b > hi + _slack(xs, n, per, hi):
            c = hi
        elif b < lo - _slack(xs, n, per, lo):
            c = lo
        else:
            continue
        th = min(max((c - a) / (b - a), 0.0), 1.0) if b != a else 0.0
        if th < best:
            best, jb, cb = th, j, c
    return best, jb, cb


@njit
def cut_back(a, b, c, over):
    """The part of a step whose variable went from ``a`` to ``b`` past the point ``c`` at
    which to end it again: the secant from the start, whose distance to the point is
    halved for each earlier attempt past it in a row (``over`` - 1 of them; Illinois'
    rule: a path that curves towards the point would otherwise be closed in on by a few
    per cent an attempt, and the attempts would run out past it).

    Examples
    --------
    >>> cut_back(0.0, 2.0, 1.0, 1), cut_back(0.0, 2.0, 1.0, 2)
    (0.5, 0.3333333333333333)
    """
    a = c + (a - c) * 0.5 ** (over - 1)
    return (c - a) / (b - a)


@njit
def aim(br, t, s, eta):
    """The step from ``t``, where a step ended short of the point of the bracket ``br``
    (its table's variable there ``s``), that aims at the point: the secant through the
    bracket's ends, the far end's distance to the point halved each time it is kept
    (Illinois' rule, ``br[2]`` counts them), just past it by ``eta``; inf where ``s`` is
    not short of the point.  ``br``: time and variable of the far end, the count, the
    first step's travel, the point, the table (``P_BRACKET`` of the DOP853 loop).

    Examples
    --------
    >>> import numpy as np
    >>> br = np.array([1.0, 2.0, 0.0, 1.0, 1.0, 0.0])
    >>> aim(br, 0.0, 0.0, 0.0), aim(br, 0.5, 0.75, 0.0), float(br[2])
    (0.5, 0.16666666666666666, 2.0)
    """
    c = br[4]
    far = c + (br[1] - c) * 0.5 ** br[2]
    br[2] += 1.0
    if (far - c) * (c - s) > 0.0:
        return (br[0] - t) * (c - s) / (far - s) * (1.0 + 0.5 * eta)
    return np.inf


@njit
def crossed(t, ip, fp, dims, sc, old, new, locks, br):
    """``(theta, j, c, aiming)`` at the end ``t`` of a step (its table variables, as
    evaluated, into ``new``): where a variable left its held piece (:func:`left`), and
    whether that is the point of the bracket ``br`` (see :func:`aim`), which the step
    then aimed at."""
    table_vars(t, ip, fp, dims, sc, new)
    th, jt, ct = left(ip, fp, old, new, locks)
    # (a bracket of this point's time: the criteria relative to the first step past it,
    # not to the short steps that aim at it)
    aiming = br[0] < np.inf and jt == int(br[5]) and ct == br[4]
    return th, jt, ct, aiming


@njit
def again(th, first, retried, aiming, h, hmin, old, jt, ct, br):
    """What becomes of a step of size ``h`` whose variables left their pieces at the part
    ``th`` of it (:func:`crossed`; at a stage, at the part ``first``; 2.0: none), taken
    ``retried`` times already: KEEP it; BACK_TO_STAGE, a variable that left its piece and
    came back within the step (a ram that, on the piece past its stop, would turn round
    there): again, up to where the first stage past the point puts it; NEXT_PIECE, at the
    point already (within ETA of the step, the smallest step, or ETA of the first step's
    travel past a point aimed at): again on the next piece; UP_TO_POINT: again, up to the
    point (just past it).  Past the point by at most ETA of the step it is kept."""
    if retried >= ATTEMPTS:
        return KEEP
    if th > 1.0 and ETA < first < 1.0 - ETA:
        return BACK_TO_STAGE
    if not th <= 1.0:
        return KEEP
    if th <= ETA or th * h <= hmin or (aiming and abs(old[jt] - ct) <= ETA * br[3]):
        return NEXT_PIECE
    if th < 1.0 - ETA:
        return UP_TO_POINT
    return KEEP


@njit
def shortened(kind, h, hmin, first, t, over, aiming, old, new, jt, ct, br):
    """``(h, over)``: the step ``h`` to ``t`` taken again shorter (``kind``, see
    :func:`again`): BACK_TO_STAGE, up to where its first stage past the point put it
    (``first``); UP_TO_POINT, up to the point ``ct`` of table ``jt`` (its variables went
    from ``old`` to ``new``: :func:`cut_back`, just past it), the bracket ``br`` of the
    point's time updated (see :func:`aim`) and ``over`` the attempts past it in a row."""
    if kind == BACK_TO_STAGE:
        return max(first * h * (1.0 + 0.5 * ETA), hmin), over
    if not aiming:
        br[3] = abs(new[jt] - old[jt])
    if not aiming or t < br[0]:
        br[0], br[1], br[2] = t, new[jt], 0.0
    over = over + 1 if aiming else 1
    br[4], br[5] = ct, jt
    return cut_back(old[jt], new[jt], ct, over) * h * (1.0 + 0.5 * ETA), over


@njit
def switch_at(th, aiming, br, old, new):
    """``(switch, ahead)`` for a step kept (:func:`crossed`): whether the next pieces are
    held from its end -- past the point by at most ETA of the step, or short of the
    bracket's point by ETA of the first step past it (``new`` then moved past it, for
    :func:`hold`) -- and the part of the step's travel past its end at which a table
    switches; the bracket dropped where the point is reached."""
    switch = th <= 1.0
    ahead = 2.0 * ETA
    if switch and aiming:
        br[0] = np.inf
    jl = int(br[5])
    if not switch and br[0] < np.inf and abs(new[jl] - br[4]) <= ETA * br[3]:
        switch = True
        ahead = min(1.0, max(ahead, 2.0 * ETA * br[3] / max(abs(new[jl] - old[jl]), 1e-300)))
        new[jl] = br[4] + (br[1] - br[4]) * ETA  # (for hold: past it)
        br[0] = np.inf
    return switch, ahead
