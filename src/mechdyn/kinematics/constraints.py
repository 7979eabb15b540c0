"""Constraint equations Phi(x) = 0 and coordinate definitions g(x) = q, exact.

All functions work on a batch: ``x`` has shape ``(..., n_x)`` and results carry
the same leading dimensions, so a whole sweep is evaluated in one call.

Per joint (r body origin, A rotation by theta, R = rotation by +90 deg):

* revolute   Phi = r_i + A_i s_i - r_j - A_j s_j                       (2 rows)
* prismatic  Phi = [n . d, theta_j - theta_i - angle],  d = r_j + A_j s_j - r_i - A_i s_i,
  u = A_i u_i the axis, n = R u its normal                             (2 rows)
* lock       Phi = [r_j - r_i - A_i c, theta_j - theta_i - angle]      (3 rows)

and the acceleration right-hand side gamma = -(Phi_x xdot)_x xdot, so that
Phi_x xddot = gamma.
"""

from __future__ import annotations

import numpy as np

from ..model import COORD_ANGLE, COORD_RELATIVE, COORD_TRAVEL, ConstraintLayout, Model

__all__ = ["residual", "jacobian", "gamma", "coordinates", "coordinates_jacobian",
           "coordinates_gamma", "system", "point_position", "point_velocity",
           "point_acceleration", "extend"]


def extend(model: Model, x: np.ndarray) -> np.ndarray:
    """Body poses with the ground appended: shape (..., n_bodies + 1, 3)."""
    x = np.asarray(x, dtype=float)
    X = x.reshape(x.shape[:-1] + (model.n_bodies, 3))
    pad = np.zeros(x.shape[:-1] + (1, 3))
    return np.concatenate([X, pad], axis=-2)


def _rot(th, s):
    """A(theta) s for th (...,n) and s (n,2) -> (..., n, 2)."""
    c, sn = np.cos(th), np.sin(th)
    return np.stack([c * s[:, 0] - sn * s[:, 1], sn * s[:, 0] + c * s[:, 1]], axis=-1)


def _perp(v):
    """Rotate vectors (..., 2) by +90 deg."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _dot(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def residual(model: Model, x, layout: ConstraintLayout | None = None) -> np.ndarray:
    """Phi(x), shape (..., n_rows) in the layout's row order (m, or rad for angle rows)."""
    lay = layout or model.layout()
    X = extend(model, x)
    out = np.empty(X.shape[:-2] + (lay.n_rows,))
    k = 0
    rv = model.rev
    n = len(rv.names)
    if n:
        pi = X[..., rv.i, :2] + _rot(X[..., rv.i, 2], rv.si)
        pj = X[..., rv.j, :2] + _rot(X[..., rv.j, 2], rv.sj)
        out[..., k:k + 2 * n] = (pi - pj).reshape(X.shape[:-2] + (2 * n,))
        k += 2 * n
    pr = model.pri
    n = len(pr.names)
    if n:
        thi, thj = X[..., pr.i, 2], X[..., pr.j, 2]
        d = X[..., pr.j, :2] + _rot(thj, pr.sj) - X[..., pr.i, :2] - _rot(thi, pr.si)
        nrm = _perp(_rot(thi, pr.ui))
        rows = np.stack([_dot(nrm, d), thj - thi - pr.angle], axis=-1)
        out[..., k:k + 2 * n] = rows.reshape(X.shape[:-2] + (2 * n,))
        k += 2 * n
    lk = model.lock
    act = lay.lock_active
    if act.any():
        i, j, c, a = lk.i[act], lk.j[act], lk.c[act], lk.angle[act]
        thi = X[..., i, 2]
        dp = X[..., j, :2] - X[..., i, :2] - _rot(thi, c)
        rows = np.concatenate([dp, (X[..., j, 2] - thi - a)[..., None]], axis=-1)
        m = int(act.sum())
        out[..., k:k + 3 * m] = rows.reshape(X.shape[:-2] + (3 * m,))
        k += 3 * m
    return out


def jacobian(model: Model, x, layout: ConstraintLayout | None = None) -> np.ndarray:
    """Phi_x, shape (..., n_rows, n_x)."""
    lay = layout or model.layout()
    X = extend(model, x)
    batch = X.shape[:-2]
    nb = model.n_bodies
    J = np.zeros(batch + (lay.n_rows, nb + 1, 3))
    k = 0
    rv = model.rev
    n = len(rv.names)
    if n:
        ai = _rot(X[..., rv.i, 2], rv.si)
        aj = _rot(X[..., rv.j, 2], rv.sj)
        rx = k + 2 * np.arange(n)
        ry = rx + 1
        J[..., rx, rv.i, 0] = 1.0
        J[..., ry, rv.i, 1] = 1.0
        J[..., rx, rv.i, 2] = -ai[..., 1]
        J[..., ry, rv.i, 2] = ai[..., 0]
        J[..., rx, rv.j, 0] = -1.0
        J[..., ry, rv.j, 1] = -1.0
        J[..., rx, rv.j, 2] = aj[..., 1]
        J[..., ry, rv.j, 2] = -aj[..., 0]
        k += 2 * n
    pr = model.pri
    n = len(pr.names)
    if n:
        thi, thj = X[..., pr.i, 2], X[..., pr.j, 2]
        ai = _rot(thi, pr.si)
        aj = _rot(thj, pr.sj)
        d = X[..., pr.j, :2] + aj - X[..., pr.i, :2] - ai
        u = _rot(thi, pr.ui)
        nrm = _perp(u)
        rn = k + 2 * np.arange(n)
        ra = rn + 1
        J[..., rn, pr.j, 0] = nrm[..., 0]
        J[..., rn, pr.j, 1] = nrm[..., 1]
        J[..., rn, pr.j, 2] = _dot(nrm, _perp(aj))
        J[..., rn, pr.i, 0] = -nrm[..., 0]
        J[..., rn, pr.i, 1] = -nrm[..., 1]
        J[..., rn, pr.i, 2] = -_dot(u, d) - _dot(nrm, _perp(ai))
        J[..., ra, pr.j, 2] = 1.0
        J[..., ra, pr.i, 2] = -1.0
        k += 2 * n
    lk = model.lock
    act = lay.lock_active
    if act.any():
        i, j, c = lk.i[act], lk.j[act], lk.c[act]
        m = int(act.sum())
        ac = _rot(X[..., i, 2], c)
        rx = k + 3 * np.arange(m)
        ry, rt = rx + 1, rx + 2
        J[..., rx, j, 0] = 1.0
        J[..., ry, j, 1] = 1.0
        J[..., rx, i, 0] = -1.0
        J[..., ry, i, 1] = -1.0
        J[..., rx, i, 2] = ac[..., 1]
        J[..., ry, i, 2] = -ac[..., 0]
        J[..., rt, j, 2] = 1.0
        J[..., rt, i, 2] = -1.0
        k += 3 * m
    return J[..., :nb, :].reshape(batch + (lay.n_rows, 3 * nb))


def gamma(model: Model, x, xdot, layout: ConstraintLayout | None = None) -> np.ndarray:
    """Acceleration right-hand side: Phi_x xddot = gamma, shape (..., n_rows)."""
    lay = layout or model.layout()
    X = extend(model, x)
    V = extend(model, xdot)
    out = np.zeros(X.shape[:-2] + (lay.n_rows,))
    k = 0
    rv = model.rev
    n = len(rv.names)
    if n:
        ai = _rot(X[..., rv.i, 2], rv.si)
        aj = _rot(X[..., rv.j, 2], rv.sj)
        wi2 = V[..., rv.i, 2, None] ** 2
        wj2 = V[..., rv.j, 2, None] ** 2
        out[..., k:k + 2 * n] = (ai * wi2 - aj * wj2).reshape(X.shape[:-2] + (2 * n,))
        k += 2 * n
    pr = model.pri
    n = len(pr.names)
    if n:
        thi, thj = X[..., pr.i, 2], X[..., pr.j, 2]
        wi, wj = V[..., pr.i, 2], V[..., pr.j, 2]
        ai = _rot(thi, pr.si)
        aj = _rot(thj, pr.sj)
        d = X[..., pr.j, :2] + aj - X[..., pr.i, :2] - ai
        dd = (V[..., pr.j, :2] + wj[..., None] * _perp(aj)
              - V[..., pr.i, :2] - wi[..., None] * _perp(ai))
        u = _rot(thi, pr.ui)
        nrm = _perp(u)
        quad = (-wi**2 * _dot(nrm, d) - 2 * wi * _dot(u, dd)
                + _dot(nrm, -(wj**2)[..., None] * aj + (wi**2)[..., None] * ai))
        out[..., k + 2 * np.arange(n)] = -quad
        k += 2 * n
    lk = model.lock
    act = lay.lock_active
    if act.any():
        i, c = lk.i[act], lk.c[act]
        m = int(act.sum())
        ac = _rot(X[..., i, 2], c)
        wi2 = V[..., i, 2, None] ** 2
        rows = np.concatenate([-ac * wi2, np.zeros(ac.shape[:-1] + (1,))], axis=-1)
        out[..., k:k + 3 * m] = rows.reshape(X.shape[:-2] + (3 * m,))
        k += 3 * m
    return out


# ---------------------------------------------------------------- coordinates
def _travel_parts(model: Model, X, idx):
    pr = model.pri
    i, j = pr.i[idx], pr.j[idx]
    thi, thj = X[..., i, 2], X[..., j, 2]
    ai = _rot(thi, pr.si[idx])
    aj = _rot(thj, pr.sj[idx])
    d = X[..., j, :2] + aj - X[..., i, :2] - ai
    u = _rot(thi, pr.ui[idx])
    return i, j, ai, aj, d, u


def coordinates(model: Model, x) -> np.ndarray:
    """g(x): the generalized coordinates measured on a pose, shape (..., n_q)."""
    X = extend(model, x)
    out = np.empty(X.shape[:-2] + (model.n_q,))
    kind = model.coord_kind
    for c in range(model.n_q):
        if kind[c] == COORD_ANGLE:
            out[..., c] = X[..., model.coord_body[c], 2]
        elif kind[c] == COORD_RELATIVE:
            jj = model.coord_joint[c]
            out[..., c] = X[..., model.rev.j[jj], 2] - X[..., model.rev.i[jj], 2]
        else:
            *_, d, u = _travel_parts(model, X, np.array([model.coord_joint[c]]))
            out[..., c] = _dot(u, d)[..., 0]
    return out + model.coord_offset


def coordinates_jacobian(model: Model, x) -> np.ndarray:
    """g_x, shape (..., n_q, n_x)."""
    X = extend(model, x)
    nb = model.n_bodies
    G = np.zeros(X.shape[:-2] + (model.n_q, nb + 1, 3))
    for c in range(model.n_q):
        kind = model.coord_kind[c]
        if kind == COORD_ANGLE:
            G[..., c, model.coord_body[c], 2] = 1.0
        elif kind == COORD_RELATIVE:
            jj = model.coord_joint[c]
            G[..., c, model.rev.j[jj], 2] += 1.0
            G[..., c, model.rev.i[jj], 2] -= 1.0
        else:
            i, j, ai, aj, d, u = _travel_parts(model, X, np.array([model.coord_joint[c]]))
            i, j = int(i[0]), int(j[0])
            ai, aj, d, u = ai[..., 0, :], aj[..., 0, :], d[..., 0, :], u[..., 0, :]
            nrm = _perp(u)
            G[..., c, j, 0] += u[..., 0]
            G[..., c, j, 1] += u[..., 1]
            G[..., c, j, 2] += _dot(u, _perp(aj))
            G[..., c, i, 0] -= u[..., 0]
            G[..., c, i, 1] -= u[..., 1]
            G[..., c, i, 2] += _dot(nrm, d) - _dot(u, _perp(ai))
    return G[..., :nb, :].reshape(X.shape[:-2] + (model.n_q, 3 * nb))


def coordinates_gamma(model: Model, x, xdot) -> np.ndarray:
    """-(g_x xdot)_x xdot, shape (..., n_q); zero for angle coordinates."""
    X = extend(model, x)
    V = extend(model, xdot)
    out = np.zeros(X.shape[:-2] + (model.n_q,))
    for c in np.flatnonzero(model.coord_kind == COORD_TRAVEL):
        i, j, ai, aj, d, u = _travel_parts(model, X, np.array([model.coord_joint[c]]))
        ai, aj, d, u = ai[..., 0, :], aj[..., 0, :], d[..., 0, :], u[..., 0, :]
        wi, wj = V[..., i[0], 2], V[..., j[0], 2]
        dd = (V[..., j[0], :2] + wj[..., None] * _perp(aj)
              - V[..., i[0], :2] - wi[..., None] * _perp(ai))
        nrm = _perp(u)
        quad = (-wi**2 * _dot(u, d) + 2 * wi * _dot(nrm, dd)
                + _dot(u, -(wj**2)[..., None] * aj + (wi**2)[..., None] * ai))
        out[..., c] = -quad
    return out


def system(model: Model, x, q, layout: ConstraintLayout | None = None):
    """Residual [Phi; g - q] and Jacobian [Phi_x; g_x] of the position problem."""
    lay = layout or model.layout()
    F = np.concatenate([residual(model, x, lay), coordinates(model, x) - q], axis=-1)
    J = np.concatenate([jacobian(model, x, lay), coordinates_jacobian(model, x)], axis=-2)
    return F, J


# ---------------------------------------------------------------- points
def point_position(model: Model, x, body: str, point) -> np.ndarray:
    """Position of a body point in the ground frame, shape (..., 2), m."""
    k = model.body_index(body)
    s = model.point_local(body, point)
    X = extend(model, x)
    return X[..., k, :2] + _rot(X[..., k, 2][..., None], s[None, :])[..., 0, :]


def point_velocity(model: Model, x, xdot, body: str, point) -> np.ndarray:
    """Velocity of a body point, shape (..., 2), m/s."""
    k = model.body_index(body)
    s = model.point_local(body, point)
    X, V = extend(model, x), extend(model, xdot)
    a = _rot(X[..., k, 2][..., None], s[None, :])[..., 0, :]
    return V[..., k, :2] + V[..., k, 2][..., None] * _perp(a)


def point_acceleration(model: Model, x, xdot, xddot, body: str, point) -> np.ndarray:
    """Acceleration of a body point, shape (..., 2), m/s^2."""
    k = model.body_index(body)
    s = model.point_local(body, point)
    X, V, W = extend(model, x), extend(model, xdot), extend(model, xddot)
    a = _rot(X[..., k, 2][..., None], s[None, :])[..., 0, :]
    return W[..., k, :2] + W[..., k, 2][..., None] * _perp(a) - (V[..., k, 2] ** 2)[..., None] * a


def _point_kinematics(model: Model, x, xdot, xddot, body: str, point):
    """Position (m), velocity (m/s) and acceleration (m/s^2) of a body point, (..., 2) each."""
    return (point_position(model, x, body, point),
            point_velocity(model, x, xdot, body, point),
            point_acceleration(model, x, xdot, xddot, body, point))
