"""Kinematic sweep: positions, velocities and accelerations over a range of one coordinate.

The sweep drives one generalized coordinate (``over``) through a sequence of
values while the other coordinates stay at their initial values, and records
the poses ``x``, the exact velocity analogs ``B = dx/dq`` and the velocities
and accelerations of every body at a constant rate of the coordinates.

How it is computed (vectorized over the positions):

1. *Coarse continuation.*  Starting from the assembled sketch, the mechanism is
   driven sequentially through a coarse subset of the values (steps of at most
   ``max_step``, 5 deg by default), predicting each step by quintic Hermite
   extrapolation through the last two solutions (their poses, velocity analogs
   ``x' = B`` and second derivatives ``x''``; a Taylor step ``x + x' h + x'' h^2/2``
   when there is only one), then Newton's method.  A step is accepted only if
   Newton converges, the sign of det [Phi_x; g_x] (the assembly branch) is
   unchanged and the corrector stays small compared with the step; otherwise
   the step is halved.  When the step falls below ``min_step`` the mechanism
   has reached a dead (or toggle) position: the sweep stops there and reports
   it, keeping everything computed before.  A *bifurcation* (change) position,
   where two branches cross and the coordinate keeps control (a parallelogram
   lying flat), is gone through instead: every accepted position is watched for
   one ahead, and near it a branch chart (:mod:`mechdyn.kinematics.branch_chart`)
   gives the positions, expects the sign change and, in step 3, the analogs
   (the limit from both sides).  ``stats.bifurcations`` lists the charts.
2. *Batched solve.*  Every value is predicted by quintic Hermite interpolation
   between the two coarse solutions around it (positions, first and second
   derivatives with respect to the swept coordinate), then polished by Newton's
   method on the whole batch at once.  Each point is checked for convergence,
   for the branch sign of its segment and for staying close to its predictor; a
   segment with a failing point is re-solved sequentially.
3. *Velocities and accelerations* of all positions in one batched solve:
   ``xdot = B qdot`` and ``xddot = B qddot + b(x, xdot)`` (here ``qddot = 0``).

The residual, Jacobian and acceleration right-hand side are the model's
constraint and coordinate rows (:mod:`mechdyn.model.rows`), the equations of
:mod:`mechdyn.model.constraints`, evaluated by a private kernel
(compiled when numba is installed) that also factors the Jacobians (sparse LU,
which gives the branch sign too).

Steps 1-2 are :func:`path_of`, step 3 :func:`sweep_motion` (kinetostatics uses both); the
building blocks are in :mod:`mechdyn.kinematics.continuation`, the records (public
names importable from here) in :mod:`mechdyn.kinematics.records`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from functools import partial

import numpy as np

from ..errors import ModelError, SingularPositionError, Status, did_you_mean
from ..model import Model, as_model
from ..model.constraints import coordinates
from .assembly import _least_squares, assemble, position_tol, singularity
from .branch_chart import ChartBook, PathProblem
from .continuation import (
    _MAX_NEWTON,
    _anchor_indices,
    _hermite5,
    _Stop,
    march_path,
    path_newton,
    path_node,
    sweep_kernel,
)
from .records import (
    DeadCentre,
    FourBarLoop,
    KinematicPoint,
    KinematicSweep,
    PointExtremes,
    SweepStats,
    SweepSummary,
    TransmissionAngle,
    _ro,
    four_bar_loops,
)

__all__ = ["sweep", "analyze", "initial_coordinates", "KinematicSweep", "KinematicPoint",
           "SweepSummary", "DeadCentre", "TransmissionAngle", "PointExtremes", "FourBarLoop",
           "four_bar_loops", "DEFAULT_MAX_STEP"]

#: largest step of the sequential coarse continuation for angle coordinates, rad (5 deg)
DEFAULT_MAX_STEP = np.deg2rad(5.0)
#: smallest step before a dead position is declared, rad (times the length scale for travels)
DEFAULT_MIN_STEP = 1e-11


def initial_coordinates(model: Model, x0=None) -> np.ndarray:
    """Initial coordinates of a model, shape (n_q,) (rad or m).

    Those given in ``mechanism.extras["initial"]["q"]`` (a mapping name -> value, as
    the model-file loader stores them, or a sequence of n_q values); the others
    measured on the pose ``x0`` (default the assembled sketch ``model.x0``).
    """
    q0 = coordinates(model, np.asarray(_start_pose(model) if x0 is None else x0, float))
    init = (model.mechanism.extras or {}).get("initial", {})
    given = init.get("q") if isinstance(init, Mapping) else None
    if given is not None and not isinstance(given, Mapping):
        q = np.asarray(given, float).reshape(-1)
        if q.shape != (model.n_q,):
            raise ModelError(f"initial q must list {model.n_q} value(s) "
                             f"({', '.join(model.coordinate_names)}), got {given!r}")
        return q
    for name, v in (given or {}).items():
        q0[model.coordinate_index(name)] = float(v)
    return q0


def _start_pose(model: Model, lay=None, fresh: bool = False) -> np.ndarray:
    """The assembled sketch ``model.x0``, assembled anew (in ``lay``'s mode) if ``fresh``."""
    x0 = getattr(model, "x0", None)
    return assemble(model, layout=lay) if x0 is None or fresh else x0


def solve_at(kern, x_guess, q, tol, max_iter=_MAX_NEWTON, error=None):
    """Pose at q by Newton from ``x_guess``, else assembled from it, with F and J there:
    by :func:`assemble` (in the declared assembly modes) or, given ``error`` (a kernel of
    some coordinates or of a switched mode's rows), by a least-squares fit of the kernel's
    equations and Newton, raising ``error(x)`` where that fails."""
    x_guess = np.asarray(x_guess, float)
    x, ok, F, J = path_newton(kern, x_guess, q, tol, max_iter)
    if ok:
        return x, F, J
    if error is None:
        x = assemble(kern.model, q, x_guess=x_guess, layout=kern.lay)
        return x, *kern.system(x, q)
    x = _least_squares(lambda xx: kern.system(xx, q), x_guess, method="trf", max_nfev=2000,
                       x_scale=kern.col_scale / kern.model.length_scale)
    x, ok, F, J = path_newton(kern, x, q, tol, max_iter=30)
    if not ok:
        raise error(x)
    return x, F, J


def _rates(model: Model, k: int, speed) -> np.ndarray:
    qdot = np.zeros(model.n_q)
    qdot[k] = 1.0 if speed is None or isinstance(speed, Mapping) else float(speed)
    for name, v in (speed.items() if isinstance(speed, Mapping) else ()):
        if name not in model.coordinate_names:
            raise ModelError("speed: " + did_you_mean(name, model.coordinate_names, "coordinate"))
        qdot[model.coordinate_index(name)] = float(v)
    if not np.all(np.isfinite(qdot)):
        raise ModelError(f"speed must be finite, got {speed!r}")
    return qdot

def sweep(mech_or_model, over: str | None = None, values=None, *, speed=None, x_start=None,
          mode=None, max_step: float | None = None, min_step: float | None = None,
          tol: float | None = None) -> KinematicSweep:
    """Positions, velocities and accelerations of a mechanism over one coordinate.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    over : str, optional
        Name of the coordinate to sweep; default the only coordinate.  The other
        coordinates stay at their initial values (``mechanism.extras["initial"]["q"]``
        if given, else measured on the assembled sketch).
    values : array_like, shape (n,), optional
        Values of the swept coordinate, rad (angles) or m (travels), visited in this
        order.  Default for an angle: a full turn from its assembled value in 1 deg
        steps (361 values).  Required for a travel coordinate.
    speed : float or mapping of str to float, optional
        Constant rate of the swept coordinate (rad/s or m/s); default 1, so that the
        velocities are the velocity analogs and the accelerations are the second-order
        analogs (per unit rate squared).  A mapping gives rates for any coordinates
        (missing ones: 0; the swept one: 1 unless given).
    x_start : array_like, shape (n_x,), optional
        Pose to start the continuation from (chooses the assembly branch; the other
        coordinates are then measured on it); default the assembled sketch ``model.x0``.
    mode : iterable of str, optional
        Engaged locks (default: the model's initial mode).
    max_step : float, optional
        Largest step of the sequential coarse continuation, rad (default 5 deg) or m
        (default 5 % of the model's length scale).
    min_step : float, optional
        Step below which the continuation gives up and reports a dead position
        (default 1e-11 rad, or 1e-11 times the length scale in m).
    tol : float, optional
        Residual tolerance of the position solve, m (default 1e-13 x length scale).

    Returns
    -------
    KinematicSweep
        ``status`` is ``"success"``, or ``"singular-position"`` when a dead or toggle
        position stopped the sweep (the positions computed before it are kept).

    Raises
    ------
    ModelError
        Unknown coordinate name, bad values.
    AssemblyError
        The mechanism cannot be assembled at the start of the sweep.
    """
    t_start = time.perf_counter()
    model = as_model(mech_or_model)
    if model.n_q == 0:
        raise ModelError("the mechanism has no coordinates to sweep")
    if over is None:
        if model.n_q != 1:
            raise ModelError("the mechanism has several coordinates; choose one with over=: "
                             + ", ".join(repr(c) for c in model.coordinate_names))
        over = model.coordinate_names[0]
    k = model.coordinate_index(over)
    is_angle = bool(model.coord_is_angle[k])
    lay = model.layout(mode)
    kern = sweep_kernel(model, lay)
    L = model.length_scale
    if tol is None:
        tol = position_tol(model)
    if max_step is None:
        max_step = DEFAULT_MAX_STEP if is_angle else 0.05 * L
    if min_step is None:
        min_step = DEFAULT_MIN_STEP if is_angle else DEFAULT_MIN_STEP * L

    # ---- start pose and coordinates
    if x_start is None:
        x0 = _start_pose(model, lay, fresh=lay.mode != model.initial_mode)
        q_init = initial_coordinates(model, x0)
    else:
        x0 = np.asarray(x_start, float).reshape(model.n_x)
        q_init = coordinates(model, x0)
    x_init, _, J0 = solve_at(kern, x0, q_init, tol)
    start = path_node(kern, x_init, q_init, k, J=J0)
    # bifurcation positions on the way are gone through on the branch (branch charts)
    book = ChartBook(PathProblem(model, lay, np.arange(model.n_q), q_init, k)) \
        if kern.square else None

    if values is None:
        if not is_angle:
            raise ModelError(f"coordinate {over!r} is a travel (m): give the values to sweep")
        values = q_init[k] + np.linspace(0.0, 2 * np.pi, 361)
    values = np.asarray(values, dtype=float).reshape(-1)
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise ModelError(f"values of {over!r} must be a non-empty sequence of finite numbers")
    n_req = values.size
    qdot_c = _rates(model, k, speed)

    counter: dict = {}
    X, stop, system = path_of(kern, start, k, values, max_step=max_step, min_step=min_step,
                            tol=tol, book=book, counter=counter)
    N = len(X)
    Q = _coords(q_init, k, values[:N])
    qdot = np.broadcast_to(qdot_c, (N, model.n_q)).copy()
    qddot = np.zeros((N, model.n_q))
    X, B, xdot, xddot, _ = sweep_motion(kern, X, Q, qdot, qddot, book, k, system)

    error, events = None, ()
    if stop is not None:
        error, event = _dead_report(model, lay, k, stop, N, n_req)
        events = (event,)
    elapsed = time.perf_counter() - t_start
    stats = SweepStats(
        n_points=int(N), n_requested=int(n_req), anchors=counter["anchors"],
        coarse_steps=int(counter.get("coarse_steps", 0)),
        rejected_steps=int(counter.get("rejected_steps", 0)),
        fallback_segments=counter["fallback"], time_s=elapsed,
        time_coarse_s=counter["time_coarse"],
        positions_per_s=N / elapsed if elapsed > 0 else np.inf,
        bifurcations=book.report() if book is not None else [],
        mode=tuple(sorted(lay.mode)))
    return KinematicSweep(
        over=over, values=_ro(values[:N].copy()), q=_ro(Q), qdot=_ro(qdot), qddot=_ro(qddot),
        x=_ro(X), xdot=_ro(xdot), xddot=_ro(xddot), B=_ro(B), stats=stats, events=events,
        status="success" if error is None else Status.SINGULAR_POSITION,
        message="" if error is None else str(error), error=error, model=model)


def path_of(kern, start, k: int, values, *, max_step, min_step, tol, book, counter):
    """The continuation of the sweep from the node ``start`` through ``values`` of
    coordinate k (the kernel's other coordinates held at ``start.q``): steps 1 and 2 of
    the module docstring.  Returns the poses reached (n_ok, n_x), the :class:`_Stop` or
    None and (F, J, factors) at the poses or None; ``counter`` gets the step counts,
    ``anchors``, ``fallback`` and ``time_coarse``."""
    model, n_req = kern.model, len(values)
    t_coarse = time.perf_counter()
    # ---- 1. coarse continuation through the anchors
    anchors = _anchor_indices(values, max_step)
    march = partial(march_path, kern, k=k, max_step=max_step, min_step=min_step, tol=tol,
                    counter=counter, book=book)
    anodes, stop = march(start, targets=values[anchors])
    n_anch = len(anodes)
    counter.update(time_coarse=time.perf_counter() - t_coarse, anchors=len(anchors),
                   fallback=0)
    # ---- 2. batched solve of every value between solved anchors
    n_ok = int(anchors[n_anch - 1]) + 1 if n_anch else 0
    X = np.empty((n_ok, model.n_x))
    system = None  # F, J and the factors at X, while they are current
    if n_anch == 1:
        X[:] = anodes[0].x
    elif n_anch > 1:
        a_idx = anchors[:n_anch]
        seg = np.clip(np.searchsorted(a_idx, np.arange(n_ok), side="right") - 1, 0, n_anch - 2)
        xa, da, aa, sg = (np.array([getattr(nd, f) for nd in anodes])
                          for f in ("x", "xs", "xss", "sign"))
        qa = values[a_idx]
        h = (qa[seg + 1] - qa[seg])[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(h != 0, (values[:n_ok, None] - qa[seg, None]) / h, 0.0)
        xp = _hermite5(t, h, xa[seg], da[seg], aa[seg], xa[seg + 1], da[seg + 1], aa[seg + 1])
        X, ok_f, F, J = path_newton(kern, xp, _coords(start.q, k, values[:n_ok]), tol, max_iter=5)
        fac = kern.factor(J)
        near = np.max(np.abs((X - xp) * kern.col_scale), axis=1) <= 1e-3 * model.length_scale
        ok_f &= (fac[2] == sg[seg]) & near
        system = (F, J, fac)
        bad_segments = np.unique(seg[~ok_f])
        for m_ in bad_segments:  # re-solve those segments point by point
            counter["fallback"] += 1
            system = None
            i0, i1 = a_idx[m_], a_idx[m_ + 1]
            nodes, st = march(anodes[m_], targets=values[i0 + 1:i1 + 1])
            for r, nd in enumerate(nodes):
                X[i0 + 1 + r] = nd.x
            if st is not None:  # only if a singular position lies between two anchors
                stop = st
                n_ok = i0 + 1 + len(nodes)
                X = X[:n_ok]
                anodes, n_anch = anodes[:m_ + 1], -1
                break

    # ---- 3. past the last anchor: go on point by point up to the dead position
    if stop is not None and n_anch >= 0 and n_ok < n_req:
        last = anodes[-1] if n_anch else start
        nxt = anchors[n_anch] if n_anch < len(anchors) else n_req - 1
        nodes, stop = march(last, targets=values[n_ok:nxt + 1])
        if stop is None:  # cannot happen: the anchor itself was unreachable
            stop = _Stop(nodes[-1], nodes[-1].q, "the continuation could not reach "
                         f"{values[nxt]:.9g}")
        if nodes:
            X = np.concatenate([X, [nd.x for nd in nodes]])
            system = None
    return X, stop, system


def sweep_motion(kern, X, Q, qdot, qddot, book, k: int, system=None, correct=True):
    """Step 3 of the module docstring: a last Newton correction of the poses X (N, n_x)
    at the coordinates Q (with ``correct``), the analogs B and the velocities and
    accelerations for the rates qdot, qddot (N, n_q), from the charts in the bifurcation
    zones of ``book`` (swept coordinate k).  Returns X, B, xdot, xddot and the charted
    samples (mask, x', x'') or None; ``system``: (F, J, factors) at X when they are current."""
    N = len(X)
    if not N:
        empty = np.empty((0, kern.n_x))
        return X, np.empty((0, kern.n_x, kern.n_q)), empty, empty, None
    if system is None:
        F, J = kern.system(X, Q)
        system = (F, J, kern.factor(J))
    F, J, fac = system
    with np.errstate(all="ignore"):  # a Jacobian singular at a bifurcation: charted
        rhs = kern.rhs_unit(N)
        if correct:
            rhs = np.concatenate([F[..., None], rhs], axis=-1)
        B = kern.apply(J, fac, rhs)
        if correct:
            X = X - B[:, :, 0]  # a last Newton correction, at round-off level
            B = B[:, :, 1:]
        xdot = np.einsum("nij,nj->ni", B, qdot)
        xddot = np.einsum("nij,nj->ni", B, qddot)
        xddot += kern.apply(J, fac, kern.gamma(X, xdot)[..., None])[..., 0]
    if book is None or not (charted := book.apply(Q[:, k]))[0].any():
        return X, B, xdot, xddot, None
    mask, xc, xs, xss = charted
    # the limit from both sides, where the equations are ill-conditioned: the analogs of
    # the other coordinates stay those of the direct solve, and so does the part of the
    # acceleration due to their rates
    X, B, xdot, xddot = X.copy(), B.copy(), xdot.copy(), xddot.copy()
    X[mask] = xc
    B[mask, :, k] = xs
    xdot[mask] = np.einsum("nij,nj->ni", B[mask], qdot[mask])
    if not np.any(np.delete(qdot[mask], k, axis=1)) and \
            not np.any(np.delete(qddot[mask], k, axis=1)):
        xddot[mask] = xss * qdot[mask, k, None] ** 2 + xs * qddot[mask, k, None]
    return X, B, xdot, xddot, (mask, xs, xss)


def _coords(q_init, k: int, values) -> np.ndarray:
    """Coordinates (n, n_q): q_init with coordinate k at the values."""
    Q = np.tile(q_init, (len(values), 1))
    Q[:, k] = values
    return Q


def _dead_report(model, lay, k, stop: _Stop, n_done, n_req):
    """SingularPositionError and event describing where the continuation stopped."""
    name = model.coordinate_names[k]
    q_last = float(stop.node.q[k])
    is_angle = bool(model.coord_is_angle[k])
    where = (f"{name} = {np.rad2deg(q_last):.6f} deg ({q_last:.9g} rad)" if is_angle
             else f"{name} = {q_last * 1e3:.6f} mm")
    direction = "beyond" if stop.q_try[k] > q_last else "below"
    try:
        rep = singularity(model, stop.node.x, lay)
    except (np.linalg.LinAlgError, ValueError):
        rep = {"rcond": np.nan, "sigma_min": np.nan, "coordinates": [], "joints": []}
    joints = ", ".join(repr(j) for j in rep["joints"]) or "-"
    msg = (f"dead position at {where}: the mechanism cannot be driven {direction} it by "
           f"{name!r} ({stop.reason}; sigma_min/sigma_max = {rep['rcond']:.2e}, joints "
           f"{joints} become dependent); {n_done} of {n_req} positions computed")
    err = SingularPositionError(msg, q=stop.node.q, sigma_min=rep["sigma_min"],
                                coordinates=[name], joints=rep["joints"])
    event = {"kind": "dead-position", "coordinate": name, "at": q_last, "index": n_done - 1,
             "q": stop.node.q.copy(), "rcond": rep["rcond"], "joints": list(rep["joints"]),
             "reason": stop.reason}
    return err, event


def analyze(mech_or_model, q, qdot, qddot=None, x_guess=None, *, mode=None) -> KinematicPoint:
    """Positions, velocities and accelerations at one set of coordinates.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    q, qdot : array_like, shape (n_q,)
        Coordinates (rad or m) and their rates (rad/s or m/s).
    qddot : array_like, shape (n_q,), optional
        Accelerations of the coordinates (default zero).
    x_guess : array_like, shape (n_x,), optional
        Starting pose for Newton (chooses the branch); default the assembled sketch.

    Returns
    -------
    KinematicPoint
    """
    model = as_model(mech_or_model)
    lay = model.layout(mode)
    kern = sweep_kernel(model, lay)
    q, qdot, qddot = (np.array(v, float).reshape(model.n_q)
                      for v in (q, qdot, np.zeros(model.n_q) if qddot is None else qddot))
    x, F, J = solve_at(kern, _start_pose(model, lay) if x_guess is None else x_guess, q,
                        position_tol(model))
    system = (F[None], J[None], kern.factor(J[None]))
    x, B, xdot, xddot, _ = sweep_motion(kern, x[None], q[None], qdot[None], qddot[None], None, 0,
                                   system, correct=False)
    return KinematicPoint(q=_ro(q), qdot=_ro(qdot), qddot=_ro(qddot),
                          x=_ro(x[0]), xdot=_ro(xdot[0]), xddot=_ro(xddot[0]), B=_ro(B[0]),
                          model=model)
