"""Poses, velocities and accelerations of a mechanism whose driven coordinates follow
a prescribed motion (batched over positions), the choice of the driven coordinates,
and the dead centres of a crank's turn.

The driving constraints ``g_d(x) - q_d = 0`` are appended to the joint constraints
``Phi(x) = 0`` (the kernel of :mod:`mechdyn.kinematics.continuation` with the driven
coordinates prescribed); the poses are found by the kinematic sweep's continuation
(branch kept by the sign of det [Phi_x; g_d,x], through bifurcation positions with the
branch charts of :mod:`mechdyn.kinematics.branch_chart`), the rates from
``[Phi_x; g_d,x] xdot = [0; qdot_d]`` and the accelerations from the same matrix with
the exact right-hand side gamma.  The dead centres are refined on a sweep of the crank.
"""

from __future__ import annotations

import numpy as np

from ..dynamics.mode_system import independent_row_indices
from ..errors import AssemblyError, ModelError, SingularPositionError
from ..kernels import rows_numpy
from ..kinematics.assembly import column_scale, joint_residuals
from ..kinematics.branch_chart import ChartBook, PathProblem
from ..kinematics.continuation import Kernel, march_path, path_newton, path_node, sweep_kernel
from ..kinematics.records import refine_root
from ..kinematics.sweep import (
    DEFAULT_MAX_STEP,
    DEFAULT_MIN_STEP,
    path_of,
    solve_at,
    sweep,
    sweep_motion,
)
from ..model import Model, as_model
from ..model.constraints import coordinates, coordinates_jacobian, point_kinematics

__all__ = ["dead_centres"]


def _steps(kern: Kernel, c: int, tol: float, counter: dict) -> dict:
    """The march's step limits for the kernel's coordinate c (those of the sweep)."""
    model = kern.model
    L = 1.0 if model.coord_is_angle[kern.idx[c]] else model.length_scale
    return {"max_step": (DEFAULT_MAX_STEP if L == 1.0 else 0.05 * L),
            "min_step": DEFAULT_MIN_STEP * L, "tol": tol, "counter": counter}


def _move(kern: Kernel, node, q, cs, tol: float, counter: dict):
    """March node's coordinates cs, one after the other, to their values in q (no chart
    book); raises where it stalls."""
    for c in cs:
        if node.q[c] != q[c]:
            nodes, stop = march_path(kern, path_node(kern, node.x, node.q, c), c, [q[c]],
                                 **_steps(kern, c, tol, counter))
            if stop is not None:
                raise _error(kern, stop.q_try, stop.node.x)
            node = nodes[-1]
    return node


def _start(kern: Kernel, q0, x_start, j: int, tol: float, counter: dict):
    """The node at the held coordinates of q0 (coordinate j as at x_start), by
    continuation from the pose x_start when it is assembled, else at q0 by the sweep's
    Newton-else-fit (:func:`~mechdyn.kinematics.sweep.solve_at`)."""
    q_s = coordinates(kern.model, x_start)[kern.idx]
    x, ok, _, J = path_newton(kern, x_start, q_s, tol, max_iter=60)
    if ok:
        try:
            return _move(kern, path_node(kern, x, q_s, j, J), q0,
                         [c for c in range(len(q0)) if c != j], tol, counter)
        except (AssemblyError, SingularPositionError):
            pass
    x, _, J = solve_at(kern, x_start, q0, tol, max_iter=60, error=lambda xx: _error(kern, q0, xx))
    return path_node(kern, x, q0, j, J)


def _error(kern: Kernel, qd, x):
    """SingularPositionError where the position solve stalls at an assembled pose x, else
    AssemblyError naming the joints (and switchable elements) that stay open."""
    model, lay = kern.model, kern.lay
    res = joint_residuals(model, x, lay)
    r = rows_numpy.values(lay.rowset, x)
    res.update({el: float(np.linalg.norm(r[idx])) for el, idx in lay.elements.items()})
    names = [model.coordinate_names[k] for k in kern.idx]
    if max(res.values(), default=0.0) < 1e-6 * model.length_scale:
        return SingularPositionError(
            "the position solve stalls near a dead, toggle or change point: the driven "
            "coordinate(s) " + ", ".join(names) + " lose control of the mechanism there "
            "(largest joint residual " + f"{max(res.values()):.3g}); analyse up to that "
            "position or choose another driven coordinate", q=qd, coordinates=names,
            joints=list(res))
    open_ = {n: v for n, v in res.items() if v > 1e-9 * max(model.length_scale, 1e-3)}
    qs = ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, np.atleast_1d(qd), strict=True))
    parts = ", ".join(f"{n!r}: {v:.3g}" for n, v in open_.items()) or "none"
    return AssemblyError(f"the mechanism cannot be assembled at {qs}; joints that stay "
                         f"open (residual, m or rad): {parts}", q=qd, residuals=open_)


def _prescribed(model: Model, lay, didx, qd, qd_dot, qd_ddot, x_start, x_guess=None):
    """Poses, velocities and accelerations (n, n_x) with the driven coordinates ``didx``
    following qd, qd_dot, qd_ddot (n, n_d): one batched Newton solve from the guesses
    x_guess when it converges everywhere, else the sweep's continuation from x_start
    (through bifurcation positions with a chart book), or through anchors when several
    driven coordinates vary.  Also returns the charted samples (mask (n,), x', x'') or
    None and the stats ``position_solves`` and ``bifurcations``."""
    kern = Kernel(model, lay, didx) if lay.extra else sweep_kernel(model, lay, didx)
    tol, n = 1e-12 * max(model.length_scale, 1e-3), len(qd)
    counter = {"coarse_steps": 0}
    var = np.flatnonzero(np.ptp(qd, axis=0) > 0) if n > 1 else []
    j = int(var[0]) if len(var) == 1 else 0
    book = None
    if len(var) == 1 and kern.square and not lay.extra:
        book = ChartBook(PathProblem(model, lay, didx, qd[0], j))
    ok = guessed = False
    if x_guess is not None:
        x, ok, F, J = path_newton(kern, x_guess, qd, tol, max_iter=30)
    if np.all(ok):
        guessed = True
        system = (F, J, kern.factor(J))
        for k in range(n if book is not None else 0):  # watch the poses for bifurcations
            if book.zone_chart(qd[k, j]) is None:
                book.watch(float(qd[k, j]), x[k])
    else:
        node = _start(kern, qd[0], np.asarray(x_start if x_guess is None else x_guess[0],
                                              dtype=float), j, tol, counter)
        if len(var) <= 1:
            x, stop, system = path_of(kern, node, j, qd[:, j], book=book,
                                    **_steps(kern, j, tol, counter))
            if stop is not None:
                raise _error(kern, stop.q_try, stop.node.x)
        else:  # about 100 anchors in sequence, then one batched solve from their analogs
            anchors = np.unique(np.r_[np.arange(0, n, max(1, n // 100)), n - 1])
            nodes = []
            for k in anchors:
                node = _move(kern, node, qd[k], var, tol, counter)
                nodes.append(node)
            a = [nodes[i] for i in np.searchsorted(anchors, np.arange(n), "right") - 1]
            pred = np.array([nd.x + nd.B @ (qk - nd.q) for nd, qk in zip(a, qd, strict=True)])
            x, ok, F, J = path_newton(kern, pred, qd, tol, max_iter=30)
            fac = kern.factor(J)
            system = (F, J, fac)
            ok &= fac[2] == np.array([nd.sign for nd in a])  # on the anchor's branch
            for k in np.flatnonzero(~ok):  # by continuation from the anchor
                x[k], system = _move(kern, a[k], qd[k], var, tol, counter).x, None
    x, _, xdot, xddot, charted = sweep_motion(kern, x, qd, qd_dot, qd_ddot, book, j, system,
                                         correct=False)
    # Newton solves: the continuation's steps and the batched solves
    stats = {"position_solves": counter["coarse_steps"] + (x_guess is not None) + (not guessed),
             "bifurcations": book.report() if book is not None else []}
    return x, xdot, xddot, charted, stats


def independent_subset(model, lay, x0, first: list[int], candidates=None) -> list[int]:
    """Extend ``first`` with coordinates that add rank, up to the DOF of the layout
    (``candidates``: the order in which the others are tried; default declared order)."""
    order = first + [k for k in (range(model.n_q) if candidates is None else candidates)
                     if k not in first]
    A = np.concatenate([rows_numpy.jacobian(lay.rowset, x0),
                        coordinates_jacobian(model, x0)[order]]) * column_scale(model)
    keep = independent_row_indices(A)
    dof = model.n_x - int(np.sum(keep < lay.n_rows))
    picked = [i - lay.n_rows for i in keep if i >= lay.n_rows]  # positions in order
    for i, k in enumerate(first):
        if i not in picked:
            raise ModelError(
                f"coordinate {model.coordinate_names[k]!r} cannot be driven in mode "
                f"{sorted(lay.mode)}: it is fixed by the other driven coordinates and the "
                f"constraints ({dof} degree(s) of freedom)")
    if len(picked) < dof:
        raise ModelError(f"the mechanism has {dof} degrees of freedom in mode "
                         f"{sorted(lay.mode)}, but only {len(picked)} coordinates can be driven")
    return [order[i] for i in picked]


def dead_centres(mech_or_model, body: str, point, *, coordinate: str = "y",
                 over: str | None = None, mode=None, n: int = 720) -> dict:
    """Extreme positions of a point over one turn of a crank coordinate.

    Parameters
    ----------
    body, point :
        The watched point (e.g. the slider's ``"F"``).
    coordinate : {"x", "y"}
        Which ground coordinate of the point.
    over : str, optional
        The crank coordinate (default the first independent coordinate).
    n : int
        Samples of the turn before refinement.

    Returns
    -------
    dict
        ``{"min": (angle_rad, value_m), "max": (angle_rad, value_m)}`` with the
        angle in [0, 2 pi) and the extreme refined to about 1e-10 rad.
    """
    model = as_model(mech_or_model)
    x_start = getattr(model, "x0", model.x_sketch)
    over_idx = [model.coordinate_index(over)] if over else []
    k = independent_subset(model, model.layout(mode), x_start, over_idx)[0]
    sw = sweep(model, model.coordinate_names[k], np.linspace(0.0, 2 * np.pi, n + 1),
               x_start=x_start, mode=mode).raise_for_status()
    c = 0 if coordinate == "x" else 1

    def quantity(x, xs, xss):  # the point's coordinate and its derivatives along the crank
        return [v[..., c] for v in point_kinematics(model, x, xs, xss, body, point)]

    y, dy, _ = quantity(sw.x, sw.B[..., k], sw.x * 0.0)
    out = {}
    for key, i in (("min", int(np.argmin(y[:-1]))), ("max", int(np.argmax(y[:-1])))):
        # the sample interval where the rate changes sign (the turn is closed)
        j = i if i == 0 or np.sign(dy[i - 1]) == np.sign(dy[i]) else i - 1
        if i == 0 and np.sign(dy[0]) == np.sign(dy[1]):
            j = n - 1
        a, v = refine_root(sw, j, quantity)
        out[key] = (float(np.mod(a, 2 * np.pi)), v)
    return out
