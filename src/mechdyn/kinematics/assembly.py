"""Position analysis: solve Phi(x) = 0, g(x) = q for the body poses x.

Newton's method from the previous solution keeps the assembly branch by
continuity; the initial assembly from the sketch uses a least-squares solve.
Failures name the joints that stay open and by how much; near-singular
Jacobians (dead and toggle positions) are reported with the coordinates that
lose control and the joints whose equations become dependent.
"""

from __future__ import annotations

import numpy as np

from ..errors import AssemblyError, SingularPositionError
from ..kernels import rows_numpy
from ..kernels.planar import cross, rotate
from ..mechanism.placement import describe_poses, initial_values, suggest_assembly_mode
from ..model import ConstraintLayout, Model
from ..model.constraints import coordinates, extend, full_jacobian, residual, system
from ..model.rows import Rows

__all__ = ["newton", "solve_position", "assemble", "find_poses", "start_coordinates",
           "joint_residuals", "singularity", "rank_report",
           "branch_sign", "turn_signs", "SINGULAR_RCOND", "DEAD_RCOND"]

#: ratio sigma_min / sigma_max of the scaled Jacobian below which a position is singular
SINGULAR_RCOND = 1e-9
#: sigma_min / sigma_max below which a position where a run could not go on is reported
#: as a dead position (the edge of the assembly region)
DEAD_RCOND = 1e-4


def column_scale(model: Model) -> np.ndarray:
    """Column scaling: lengths as they are, rotations times the length scale."""
    return np.tile([1.0, 1.0, model.length_scale], model.n_bodies)


def position_tol(model: Model) -> float:
    """Default residual tolerance of the position solve: 1e-13 x the length scale, m."""
    return 1e-13 * max(model.length_scale, 1e-3)


def _fmt_len(v: float) -> str:
    v = abs(float(v))
    if v >= 1e-3:
        return f"{v * 1e3:.4g} mm"
    if v >= 1e-6:
        return f"{v * 1e6:.4g} um"
    return f"{v:.3g} m"


def joint_residuals(model: Model, x, layout: ConstraintLayout | None = None) -> dict:
    """Norm of each joint's residual at one pose, largest first (m; rad for angle rows)."""
    lay = layout or model.layout()
    r = residual(model, x, lay)
    res = {n: float(np.linalg.norm(r[rows])) for n, rows in lay.rows.items()}
    return dict(sorted(res.items(), key=lambda kv: -kv[1]))


def newton(rows: Rows, x_guess, target, *, sel=None, tol: float, max_iter: int = 40,
           system=None, solve=None):
    """The one position Newton solve of the package: rows(x)[sel] = target (batched).

    Parameters
    ----------
    rows : Rows
        The constraint and coordinate rows (:mod:`mechdyn.model.rows`).
    x_guess : array_like, shape (..., n_x)
        Start, usually the previous solution (which keeps the assembly branch).
    target : array_like, shape (..., n_sel)
        Values the selected rows must take (0 for a constraint, q for a coordinate).
    sel : array_like of int, optional
        The rows solved for (default all); their number must be n_x for a unique pose.
    tol : float
        Residual tolerance (m, or rad for angle rows).
    system : callable, optional
        ``system(x) -> (values, jacobian)`` of the selected rows at poses (..., n_x), for
        another evaluator of the same rows (the compiled kernel of the sweep); default
        :mod:`mechdyn.kernels.rows_numpy`.
    solve : callable, optional
        ``solve(J, F) -> dx`` with J dx = F, J (..., n_sel, n_x) and F (..., n_sel);
        default a dense solve, least squares where J is singular or not square.

    Returns
    -------
    x : ndarray, shape (..., n_x)
    done : ndarray of bool, shape (...)
        Converged (or stagnating at round-off, below ``1e3 tol``).

    Examples
    --------
    >>> from mechdyn.model import rows as R
    >>> r = R.angle("phi", 0, nb=1)
    >>> x, done = newton(r, [0.0, 0.0, 0.0], [0.3], tol=1e-14)
    >>> float(x[2]), bool(done)
    (0.3, True)
    """
    target = np.asarray(target, dtype=float)
    x = np.array(x_guess, dtype=float, copy=True)
    batch = np.broadcast_shapes(target.shape[:-1], x.shape[:-1])
    x = np.broadcast_to(x, batch + (rows.n_x,)).copy()
    sel = np.arange(len(rows)) if sel is None else np.asarray(sel)
    prev = np.inf
    for _ in range(max_iter):
        if system is None:
            p = rows_numpy.Parts(rows, x)
            F = rows_numpy.values(rows, x, p)[..., sel] - target
        else:
            F, J = system(x)
            F = F - target
        err = np.max(np.abs(F), axis=-1) if F.shape[-1] else np.zeros(batch)
        # converged, or stagnating at round-off level (a NaN error is neither)
        done = (err <= tol) | ((err >= 0.5 * prev) & (err <= 1e3 * tol))
        if np.all(done) or not np.all(np.isfinite(x)):
            break
        prev = err
        if system is None:
            J = rows_numpy.jacobian(rows, x, p)[..., sel, :]
        dx = solve(J, F) if solve else _dense_solve(J, F[..., None])[..., 0]
        x = x - np.where(done[..., None], 0.0, dx)
    else:
        F = (rows_numpy.values(rows, x)[..., sel] if system is None else system(x)[0]) - target
        done = np.max(np.abs(F), axis=-1) <= 1e3 * tol if F.shape[-1] else np.ones(batch, bool)
    return x, done


def solve_position(model: Model, q, x_guess, *, layout: ConstraintLayout | None = None,
                   tol: float | None = None, max_iter: int = 30, t: float | None = None,
                   check_singular: bool = True) -> np.ndarray:
    """Newton solve of [Phi(x); g(x) - q] = 0 from ``x_guess`` (batched).

    Parameters
    ----------
    model : Model
    q : array_like, shape (..., n_q)
        Generalized coordinates (rad or m).
    x_guess : array_like, shape (..., n_x)
        Start, usually the previous solution (which keeps the assembly branch).
    tol : float, optional
        Residual tolerance, default ``1e-13 * length_scale`` (m).
    t : float, optional
        Time, only for the error message.

    Returns
    -------
    x : ndarray, shape (..., n_x)

    Raises
    ------
    AssemblyError
        No convergence; the message names the joints that stay open.
    SingularPositionError
        The Jacobian is singular at the solution (dead or toggle position).
    """
    lay = layout or model.layout()
    q = np.asarray(q, dtype=float)
    if tol is None:
        tol = position_tol(model)
    zeros = np.zeros(q.shape[:-1] + (len(lay.rowset),))
    x, done = newton(lay.position_rows, x_guess, np.concatenate([zeros, q], axis=-1), tol=tol,
                     max_iter=max_iter)
    if not np.all(done):
        bad = np.unravel_index(np.argmax(~done), done.shape)
        raise _assembly_error(model, q[bad] if q.ndim > 1 else q, x[bad], lay, t)
    if check_singular:
        _check_singular(model, x, q, lay, t)
    return x


def _dense_solve(J, rhs):
    """y with J y = rhs, rhs (..., n, k): dense, least squares (minimum norm) where J is
    singular or not square."""
    try:
        y = np.linalg.solve(J, rhs)
        if np.all(np.isfinite(y)):
            return y
    except np.linalg.LinAlgError:
        pass
    return np.linalg.pinv(J) @ rhs


def _assembly_error(model, q, x_start, lay, t):
    """Find the closest configuration by least squares and say which joints stay open."""
    q = np.asarray(q, float)
    x = x_start if np.all(np.isfinite(x_start)) else model.x_sketch
    try:  # the coordinates are honoured much more strongly than the joints
        w = np.r_[np.ones(lay.n_rows), np.full(model.n_q, 1e3)]
        x = _least_squares(lambda xx: system(model, xx, q, lay), x, w, method="lm")
    except Exception:  # noqa: BLE001 - keep the Newton iterate for the report
        pass
    res = joint_residuals(model, x, lay)
    open_ = {n: v for n, v in res.items() if v > 1e-9 * max(model.length_scale, 1e-3)}
    if not open_:
        open_ = dict(list(res.items())[:2])
    gap = sum(v for n, v in open_.items() if model.joint_kind(n) == "revolute")
    parts = ", ".join(f"{n!r}: {_fmt_len(v)}" for n, v in open_.items())
    qs = ", ".join(f"{n} = {v:.6g}" for n, v in zip(model.coordinate_names, np.atleast_1d(q),
                                                    strict=False))
    msg = (f"the mechanism cannot be assembled at {qs}: the loop through joints "
           f"{', '.join(repr(n) for n in open_)} does not close by about {_fmt_len(gap)} "
           f"(closest gaps: {parts}); a link is too short or too long for this position")
    return AssemblyError(msg, t=t, q=q, residuals=open_)


def singularity(model: Model, x, layout: ConstraintLayout | None = None) -> dict:
    """Singular-value report of the scaled position Jacobian [Phi_x; g_x] at one pose.

    Returns
    -------
    dict with ``rcond`` (sigma_min / sigma_max), ``sigma_min``, ``coordinates``
    (coordinates whose equations carry the left null vector: they lose control)
    and ``joints`` (joints whose equations become dependent).
    """
    lay = layout or model.layout()
    Js = scaled_by_columns(model, full_jacobian(model, x, lay), lay.position_rows.is_angle)
    return singular_report(Js, lay.row_joint, model.coordinate_names)


def scaled_by_columns(model: Model, J, is_angle) -> np.ndarray:
    """J (..., n_r, n_x) made dimensionless: rows in m divided by the length scale L (rows
    in rad as they are), the x and y columns times L."""
    L = model.length_scale
    return J * np.where(is_angle, 1.0, 1.0 / L)[:, None] * np.tile([L, L, 1.0], model.n_bodies)


def singular_report(Js, rows, coords) -> dict:
    """The report of :func:`singularity` from a scaled Jacobian ``Js`` whose rows are the
    constraint rows (their elements ``rows``), then the coordinates ``coords``."""
    if not Js.size:
        return {"rcond": 1.0, "sigma_min": np.nan, "coordinates": [], "joints": []}
    u, s, _ = np.linalg.svd(Js)
    share = u[:, -1] ** 2
    n_r = len(rows)
    return {"rcond": float(s[-1] / s[0]) if s[0] > 0 else 0.0, "sigma_min": float(s[-1]),
            "coordinates": [c for c, w in zip(coords, share[n_r:], strict=True) if w > 1e-3],
            "joints": sorted({r for r, w in zip(rows, share[:n_r], strict=True) if w > 1e-3})}


def _check_singular(model, x, q, lay, t):
    if model.n_x == 0 or lay.n_rows + model.n_q != model.n_x:
        return
    Js = scaled_by_columns(model, full_jacobian(model, x, lay), lay.position_rows.is_angle)
    s = np.linalg.svd(Js, compute_uv=False)
    rc = s[..., -1] / s[..., 0]
    if np.any(rc < SINGULAR_RCOND):
        k = np.unravel_index(np.argmin(rc), rc.shape)
        rep = singular_report(Js[k], lay.row_joint, model.coordinate_names)
        raise SingularPositionError(
            f"dead or toggle position: the constraint Jacobian is singular "
            f"(sigma_min/sigma_max = {rep['rcond']:.2e}); coordinate(s) "
            f"{', '.join(rep['coordinates']) or '-'} lose control, joints "
            f"{', '.join(rep['joints']) or '-'} become dependent",
            t=t, q=q[k] if q.ndim > 1 else q, sigma_min=rep["sigma_min"],
            coordinates=rep["coordinates"], joints=rep["joints"])


def branch_sign(model: Model, x, layout: ConstraintLayout | None = None) -> np.ndarray:
    """Sign of det [Phi_x; g_x] (batched): it changes only through a singular position,
    so a change between two solves means the assembly branch was left."""
    J = full_jacobian(model, x, layout)
    if J.shape[-1] != J.shape[-2]:
        return np.ones(np.shape(x)[:-1])
    return np.sign(np.linalg.det(J * column_scale(model)))


def _world(X, b, s):
    """Ground-frame position of the point(s) s (..., 2) of body b, poses X (..., nb + 1, 3)."""
    return X[..., b, :2] + rotate(X[..., b, 2], s)


def turn_signs(model: Model, x) -> dict:
    """Turn P -> Q -> R of every declared assembly mode at pose(s) ``x``.

    Returns
    -------
    dict
        name -> +1 (left, counter-clockwise), -1 (right) or 0 (straight: a toggle
        position), an array for a batch of poses.
    """
    X = extend(model, x)
    out = {}
    for am, ((bp, sp), (bq, sq), (br, sr)) in model.assembly_modes:
        P, Q, R = _world(X, bp, sp), _world(X, bq, sq), _world(X, br, sr)
        a, b = Q - P, R - Q
        out[am.name] = np.sign(cross(a, b))
    return out


def _wrong_modes(model: Model, x) -> list:
    """(mode, its points P, Q, R) of the declared assembly modes x is not in."""
    signs = turn_signs(model, x)
    return [(am, pts) for am, pts in model.assembly_modes if signs[am.name] != am.sign]


def _mirror_guess(model: Model, x, pts) -> np.ndarray:
    """Sketch with the bodies that meet at Q mirrored across the line P-R
    (each body refitted as a rigid body to its mirrored points)."""
    X = extend(model, x)
    (bp, sp), (bq, sq), (br, sr) = pts
    P, Q, R = _world(X, bp, sp), _world(X, bq, sq), _world(X, br, sr)
    d = R - P
    n = np.hypot(*d)
    if n == 0:
        return np.asarray(x, float)
    d = d / n
    xg = np.array(x, dtype=float)
    tol = 1e-6 * model.length_scale
    for k, name in enumerate(model.body_names):
        body = model.mechanism.bodies[name]
        local = np.array([body.point(p) for p in body.point_names()] + [(0.0, 0.0)])
        world = _world(X, k, local)
        if not np.any(np.hypot(*(world - Q).T) < tol) or k in (bp, br):
            continue
        rel = world - P
        mirrored = P + 2 * np.outer(rel @ d, d) - rel
        # rigid fit (rotation only): angle from the centred cross-covariance
        lc, mc = local - local.mean(0), mirrored - mirrored.mean(0)
        th = np.angle(np.vdot(lc @ [1, 1j], mc @ [1, 1j]))
        origin = mirrored.mean(0) - rotate(th, local.mean(0))
        # keep the angle on the branch of the sketch angle (no 2 pi jumps)
        th = xg[3 * k + 2] + np.angle(np.exp(1j * (th - xg[3 * k + 2])))
        xg[3 * k:3 * k + 3] = (origin[0], origin[1], th)
    return xg


def assemble(model: Model, q=None, *, x_guess=None, layout=None, t=None) -> np.ndarray:
    """Assemble the mechanism at coordinates ``q`` in the declared assembly modes.

    See :func:`_assemble_near` for the solve; when the mechanism declares
    assembly modes (:class:`~mechdyn.mechanism.assembly_mode.AssemblyMode`) and the
    sketch lands on the other branch of a loop, the bodies meeting at that loop's
    point Q are mirrored and the mechanism re-assembled from there.  When some bodies
    were given without a pose (and neither ``q`` nor ``x_guess`` is given), the poses
    are found by :func:`find_poses`.

    Raises
    ------
    AssemblyError
        If the declared mode cannot be reached, or (poses omitted) if several
        assembly branches fit and nothing picks one.
    """
    if (q is None and x_guess is None and not np.all(getattr(model, "pose_given", True))
            and not getattr(model, "found_poses", None)):
        return find_poses(model, layout=layout, t=t)
    if q is None:
        q = coordinates(model, model.x_sketch if x_guess is None else np.asarray(x_guess, float))
    x = _assemble_near(model, q, x_guess=x_guess, layout=layout, t=t)
    return _in_modes(model, q, x, layout, t)


def _in_modes(model: Model, q, x, layout, t) -> np.ndarray:
    """``x`` (assembled at q) moved into the declared assembly modes by mirroring."""
    for _ in range(len(model.assembly_modes)):
        wrong = _wrong_modes(model, x)
        if not wrong:
            return x
        x = _assemble_near(model, q, x_guess=_mirror_guess(model, x, wrong[0][1]),
                           layout=layout, t=t)
    wrong = _wrong_modes(model, x)
    if wrong:
        names = ", ".join(f"{am.name!r} (declared {am.turn!r})" for am, _ in wrong)
        raise AssemblyError(
            f"the declared assembly mode(s) {names} could not be reached from the sketch; "
            "draw the sketch in the declared mode or check the points P, Q, R", t=t, q=q)
    return x


#: random starts of :func:`find_poses` besides the placement itself
N_STARTS = 15


def start_coordinates(model: Model) -> np.ndarray:
    """The coordinates at which omitted poses are found, shape (n_q,): the declared initial
    values (:func:`~mechdyn.mechanism.placement.initial_values`), the others as the
    start placement has them (rad or m)."""
    q = coordinates(model, model.x_sketch)
    for name, v in initial_values(model.mechanism).items():
        if name in model.coordinate_names:
            q[model.coordinate_index(name)] = v
    return q


def find_poses(model: Model, *, layout=None, t=None, n_starts: int = N_STARTS) -> np.ndarray:
    """Assemble a mechanism some of whose bodies have no pose, at the initial coordinates.

    The start placement (``model.x_sketch``, :mod:`mechdyn.mechanism.placement`) and
    ``n_starts`` seeded random starts (the unposed bodies turned at random) are each
    assembled at :func:`start_coordinates` and moved into the declared assembly modes;
    the distinct solutions are the branches.  One branch: it is taken.  Several: the one
    nearest the given poses if they pick one clearly, else an error lists the branches
    and an assembly mode that tells them apart.  The poses found are recorded on a model
    not yet frozen (``x_sketch``, ``found_poses``).

    Returns
    -------
    x : ndarray, shape (n_x,)

    Raises
    ------
    AssemblyError
        No start assembles (the message of the last failure), or several branches fit.

    Examples
    --------
    >>> from mechdyn import Mechanism
    >>> m = Mechanism("pendulum")
    >>> _ = m.add_body("bar", mass=1.0, points={"P": (0.2, 0.0)})
    >>> _ = m.add_revolute("O", "ground", "bar", (0.0, 0.0), "P")
    >>> _ = m.add_coordinate("theta", kind="angle", body="bar")
    >>> _ = m.set_initial(q={"theta": 0.5})
    >>> model = m.compile()
    >>> [round(float(v), 6) for v in model.found_poses["bar"]]
    [-0.175517, -0.095885, 0.5]
    """
    lay = layout or model.layout()
    q = start_coordinates(model)
    rng = np.random.default_rng(0)
    free = np.repeat(~np.asarray(model.pose_given, bool), 3)
    L = model.length_scale
    sols, error = [], None
    for k in range(n_starts + 1):
        xs = np.array(model.x_sketch, float)
        if k:
            jitter = np.tile([L, L, np.pi], model.n_bodies) * rng.uniform(-1, 1, model.n_x)
            xs = np.where(free, xs + jitter, xs)
        try:
            x = _in_modes(model, q, _assemble_near(model, q, x_guess=xs, layout=lay, t=t),
                          lay, t)
        except (AssemblyError, SingularPositionError, np.linalg.LinAlgError) as exc:
            error = exc
            continue
        if not any(_same_pose(model, x, y) for y in sols):
            sols.append(x)
    if not sols:
        raise error
    x = _pick_branch(model, sols, q, lay, t)
    # each angle on the turn of its start (an angle coordinate's value is kept as given)
    x[2::3] = model.x_sketch[2::3] + np.angle(np.exp(1j * (x[2::3] - model.x_sketch[2::3])))
    if not model.__dict__.get("_frozen", False):
        model.x_sketch = np.array(x)
        model.found_poses = {n: tuple(float(v) for v in x[3 * k:3 * k + 3])
                             for k, n in enumerate(model.body_names) if not model.pose_given[k]}
    return x


def _same_pose(model: Model, a, b) -> bool:
    """Whether two poses are one (angles modulo 2 pi)."""
    d = np.asarray(a, float) - np.asarray(b, float)
    d[2::3] = np.angle(np.exp(1j * d[2::3]))
    tol = 1e-7
    return bool(np.all(np.abs(d[0::3]) <= tol * model.length_scale)
                and np.all(np.abs(d[1::3]) <= tol * model.length_scale)
                and np.all(np.abs(d[2::3]) <= tol))


def _pick_branch(model: Model, sols: list, q, lay, t) -> np.ndarray:
    """The one branch of ``sols`` (see :func:`find_poses`), or an AssemblyError."""
    if len(sols) == 1:
        return sols[0]
    J = full_jacobian(model, sols[0], lay) * column_scale(model)
    if _rank(J) < model.n_x:  # not a set of branches: the coordinates do not fix the
        return sols[0]        # pose (the rank check of the compiler reports it)
    given = np.repeat(np.asarray(model.pose_given, bool), 3)
    if given.any():
        d = np.array([np.linalg.norm(((x - model.x_sketch) / column_scale(model))[given])
                      for x in sols])
        order = np.argsort(d)
        if d[order[1]] > 2.0 * d[order[0]] + 1e-6:
            return sols[order[0]]
    raise AssemblyError(ambiguity_message(model, sols, q), t=t, q=q)


def ambiguity_message(model: Model, sols: list, q) -> str:
    """The message of several assembly branches fitting the joints at ``q``: the branches
    (the poses that differ, mm and deg) and an assembly mode that tells them apart."""
    mech = model.mechanism
    poses = [{n: tuple(x[3 * k:3 * k + 3]) for k, n in enumerate(model.body_names)}
             for x in sols]
    qs = ", ".join(f"{n} = {np.rad2deg(v) if a else 1e3 * v:.6g} {'deg' if a else 'mm'}"
                   for n, v, a in zip(model.coordinate_names, q, model.coord_is_angle,
                                      strict=True))
    declared = ", ".join(repr(am.name) for am, _ in model.assembly_modes)
    lines = [f"{len(sols)} assembly branches fit the joints at {qs}, and "
             + (f"the declared assembly mode(s) {declared} do not pick one"
                if declared else "no assembly mode is declared to pick one")]
    differ = [n for n in model.body_names
              if any(not _same_pose(model, poses[0][n], p[n]) for p in poses[1:])]
    for k, p in enumerate(poses[:4], 1):
        lines.append(f"branch {k}: " + describe_poses({n: p[n] for n in differ}))
    hint = suggest_assembly_mode(mech, *poses)
    if hint:
        lines.append(hint)
    else:
        lines.append("declare assembly modes (mech.add_assembly_mode, [[assembly]] in a "
                     "model file) whose turns P -> Q -> R tell the branches apart")
    lines.append("or give a rough pose of " + ", ".join(repr(n) for n in differ)
                 + ": the nearest branch is taken")
    return "; ".join(lines)


def _assemble_near(model: Model, q, *, x_guess=None, layout=None, t=None) -> np.ndarray:
    """Assemble the mechanism from the sketch (or ``x_guess``) at coordinates ``q``: a
    least-squares solve pulls the sketch onto the constraints (choosing the branch
    nearest to the sketch), then Newton polishes."""
    lay = layout or model.layout()
    x = np.array(model.x_sketch if x_guess is None else x_guess, dtype=float)
    q = np.asarray(q, dtype=float)
    if model.n_x == 0:
        return x
    try:
        return solve_position(model, q, x, layout=lay, t=t, check_singular=False, max_iter=8)
    except AssemblyError:
        pass
    x = _least_squares(lambda xx: system(model, xx, q, lay), x, method="trf", max_nfev=2000,
                       x_scale=column_scale(model) / model.length_scale)
    return solve_position(model, q, x, layout=lay, t=t, check_singular=False)


def _least_squares(fun, x, w=1.0, **options) -> np.ndarray:
    """The pose nearest to w F = 0 from x, ``fun(x) -> (F, J)``, by SciPy's least_squares."""
    w = np.asarray(w, dtype=float)
    from scipy.optimize import least_squares
    return least_squares(lambda xx: fun(xx)[0] * w, x, jac=lambda xx: fun(xx)[1] * w[..., None],
                         xtol=1e-15, ftol=1e-15, gtol=1e-15, **options).x


def rank_report(model: Model, x, layout=None) -> dict:
    """Ranks at a pose: constraint rank, redundant joints, dependent coordinates."""
    lay = layout or model.layout()
    J = full_jacobian(model, x, lay) * column_scale(model)
    P, Gq = J[:lay.n_rows], J[lay.n_rows:]
    rank_phi, redundant = redundant_rows(P)
    rank_full = _rank(J)
    dep = []
    if model.n_q and rank_full < rank_phi + model.n_q:
        # coordinate c depends on the others if dropping its row keeps the rank
        dep = [model.coordinate_names[c] for c in range(model.n_q)
               if _rank(np.concatenate([P, np.delete(Gq, c, axis=0)])) == rank_full]
    return {"rank_phi": rank_phi, "redundant_joints": sorted({lay.row_joint[r] for r in redundant}),
            "dependent_coordinates": dep}


def _rank(A, rtol=1e-9):
    """Number of singular values of A above ``rtol`` times the largest (batched)."""
    return np.linalg.matrix_rank(A, rtol=rtol)


def redundant_rows(P, rtol=1e-9):
    """(rank, dependent rows) of a scaled constraint Jacobian P (n_rows, n_x), or of the one
    of least rank of a batch (..., n_rows, n_x): the dependent rows are linear combinations
    of the others (they carry the left null space)."""
    r = _rank(P, rtol)
    k = np.unravel_index(np.argmin(r), np.shape(r))
    null = np.linalg.svd(P[k])[0][:, r[k]:]
    return int(r[k]), np.flatnonzero(np.sum(null**2, axis=1) > 1e-6)
