"""Constraint equations Phi(x) = 0 and coordinate definitions g(x) = q of a model.

All functions work on a batch: ``x`` has shape ``(..., n_x)`` and results carry
the same leading dimensions, so a whole sweep is evaluated in one call.  The
rows are those the model lowered (:mod:`mechdyn.model.rows`), evaluated by
:mod:`mechdyn.kernels.rows_numpy`; the acceleration right-hand side is
gamma = -(Phi_x xdot)_x xdot, so that Phi_x xddot = gamma.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..kernels import rows_numpy
from ..kernels.planar import perp, rotate
from . import ConstraintLayout, Model
from . import rows as R

__all__ = ["full_jacobian", "full_gamma", "residual", "jacobian", "gamma", "coordinates",
           "coordinates_jacobian", "coordinates_gamma", "system", "travel_rows",
           "point_position", "point_velocity", "point_acceleration", "extend"]


def extend(model: Model, x: np.ndarray) -> np.ndarray:
    """Body poses with the ground appended: shape (..., n_bodies + 1, 3)."""
    x = np.asarray(x, dtype=float)
    X = x.reshape(x.shape[:-1] + (model.n_bodies, 3))
    pad = np.zeros(x.shape[:-1] + (1, 3))
    return np.concatenate([X, pad], axis=-2)


def residual(model: Model, x, layout: ConstraintLayout | None = None) -> np.ndarray:
    """Phi(x), shape (..., n_rows) in the layout's row order (m, or rad for angle rows)."""
    return rows_numpy.values((layout or model.layout()).rowset, x)


def jacobian(model: Model, x, layout: ConstraintLayout | None = None) -> np.ndarray:
    """Phi_x, shape (..., n_rows, n_x)."""
    return rows_numpy.jacobian((layout or model.layout()).rowset, x)


def gamma(model: Model, x, xdot, layout: ConstraintLayout | None = None) -> np.ndarray:
    """Acceleration right-hand side: Phi_x xddot = gamma, shape (..., n_rows)."""
    return -rows_numpy.quad((layout or model.layout()).rowset, x, xdot)


def coordinates(model: Model, x) -> np.ndarray:
    """g(x): the generalized coordinates measured on a pose, shape (..., n_q)."""
    return rows_numpy.values(model.coordinate_rows, x)


def coordinates_jacobian(model: Model, x) -> np.ndarray:
    """g_x, shape (..., n_q, n_x)."""
    return rows_numpy.jacobian(model.coordinate_rows, x)


def coordinates_gamma(model: Model, x, xdot) -> np.ndarray:
    """-(g_x xdot)_x xdot, shape (..., n_q); zero for angle coordinates."""
    return -rows_numpy.quad(model.coordinate_rows, x, xdot)


def system(model: Model, x, q, layout: ConstraintLayout | None = None):
    """Residual [Phi; g - q] and Jacobian [Phi_x; g_x] of the position problem."""
    rows = (layout or model.layout()).position_rows
    p = rows_numpy.Parts(rows, x)
    F = rows_numpy.values(rows, x, p)
    F[..., len(rows) - model.n_q:] -= q
    return F, rows_numpy.jacobian(rows, x, p)


def full_jacobian(model: Model, x, layout: ConstraintLayout | None = None) -> np.ndarray:
    """[Phi_x; g_x], shape (..., n_rows + n_q, n_x)."""
    return rows_numpy.jacobian((layout or model.layout()).position_rows, x)


def full_gamma(model: Model, x, xdot, layout: ConstraintLayout | None = None) -> np.ndarray:
    """[gamma; gamma_g], shape (..., n_rows + n_q): [Phi_x; g_x] xddot = it + [0; qddot]."""
    return -rows_numpy.quad((layout or model.layout()).position_rows, x, xdot)


def travel_rows(model: Model, joint: str) -> R.Rows:
    """The travel of a prismatic joint as one row, u . (r_P - r_O) (m), for the evaluators.

    r_P is the child point, r_O the parent point of the line and u the axis turned
    with the parent: the row a travel coordinate on ``joint`` lowers to, without
    its offset.

    Raises
    ------
    ModelError
        If ``joint`` is not a prismatic joint.
    """
    if model.joint_kind(joint) != "prismatic":
        raise ModelError(f"joint {joint!r} is not a prismatic joint; prismatic joints: "
                         + (", ".join(repr(v) for v in model.pri.names) or "(none)"))
    return model.joint_variable(joint, joint)


# ---------------------------------------------------------------- points
def _arm(model: Model, x, body: str, point):
    """Body index k, poses with the ground X and the arm A(theta_k) s of a body point."""
    k = model.body_index(body)
    X = extend(model, x)
    return k, X, rotate(X[..., k, 2], model.point_local(body, point))


def point_position(model: Model, x, body: str, point) -> np.ndarray:
    """Position of a body point in the ground frame, shape (..., 2), m."""
    k, X, a = _arm(model, x, body, point)
    return X[..., k, :2] + a


def point_velocity(model: Model, x, xdot, body: str, point) -> np.ndarray:
    """Velocity of a body point, shape (..., 2), m/s."""
    k, _, a = _arm(model, x, body, point)
    V = extend(model, xdot)
    return V[..., k, :2] + V[..., k, 2][..., None] * perp(a)


def point_acceleration(model: Model, x, xdot, xddot, body: str, point) -> np.ndarray:
    """Acceleration of a body point, shape (..., 2), m/s^2."""
    k, _, a = _arm(model, x, body, point)
    V, W = extend(model, xdot), extend(model, xddot)
    return W[..., k, :2] + W[..., k, 2][..., None] * perp(a) - (V[..., k, 2] ** 2)[..., None] * a


def point_kinematics(model: Model, x, xdot, xddot, body: str, point):
    """Position (m), velocity (m/s) and acceleration (m/s^2) of a body point, (..., 2) each."""
    return (point_position(model, x, body, point),
            point_velocity(model, x, xdot, body, point),
            point_acceleration(model, x, xdot, xddot, body, point))
