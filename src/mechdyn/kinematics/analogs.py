"""Velocity analogs (first transmission functions), velocities and accelerations.

Exact: [Phi_x; g_x] B = [0; I] gives B = dx/dq, shape (n_x, n_q); the
acceleration bias b solves [Phi_x; g_x] b = [gamma; gamma_g], so that
xdot = B qdot and xddot = B qddot + b(x, xdot).

The source paper's *partial systems* give the same analogs by central
differences: freeze every coordinate but q_k, displace it by +-d and re-solve
the positions, B_k ~ (x(q + d e_k) - x(q - d e_k)) / (2 d), error O(d^2).
"""

from __future__ import annotations

import numpy as np

from ..model import ConstraintLayout, Model
from ..model.constraints import full_gamma, full_jacobian
from .assembly import solve_position

__all__ = ["velocity_analogs", "acceleration_bias", "velocities", "accelerations",
           "finite_difference_analogs", "default_displacement", "DEFAULT_ANGLE_STEP"]

#: the paper's virtual displacement for angle coordinates, 0.1 deg in rad
DEFAULT_ANGLE_STEP = np.deg2rad(0.1)


def _solve(J, rhs):
    if J.shape[-1] == J.shape[-2]:
        return np.linalg.solve(J, rhs)
    return np.linalg.pinv(J) @ rhs


def velocity_analogs(model: Model, x, layout: ConstraintLayout | None = None,
                     J=None) -> np.ndarray:
    """Exact velocity analogs B = dx/dq, shape (..., n_x, n_q) (``J``: [Phi_x; g_x] at x)."""
    lay = layout or model.layout()
    if J is None:
        J = full_jacobian(model, x, lay)
    rhs = np.zeros(J.shape[:-2] + (J.shape[-2], model.n_q))
    rhs[..., lay.n_rows:, :] = np.eye(model.n_q)
    return _solve(J, rhs)


def acceleration_bias(model: Model, x, xdot, layout: ConstraintLayout | None = None,
                      J=None) -> np.ndarray:
    """b(x, xdot): the part of xddot not proportional to qddot, shape (..., n_x)."""
    lay = layout or model.layout()
    if J is None:
        J = full_jacobian(model, x, lay)
    return _solve(J, full_gamma(model, x, xdot, lay)[..., None])[..., 0]


def velocities(model: Model, x, qdot, layout=None, B=None) -> np.ndarray:
    """xdot = B qdot, shape (..., n_x) (m/s and rad/s)."""
    if B is None:
        B = velocity_analogs(model, x, layout)
    return (B @ np.asarray(qdot, float)[..., None])[..., 0]


def accelerations(model: Model, x, xdot, qddot, layout=None, B=None) -> np.ndarray:
    """xddot = B qddot + b, shape (..., n_x) (m/s^2 and rad/s^2)."""
    lay = layout or model.layout()
    J = full_jacobian(model, x, lay)
    if B is None:
        B = velocity_analogs(model, x, lay, J=J)
    return (B @ np.asarray(qddot, float)[..., None])[..., 0] + acceleration_bias(
        model, x, xdot, lay, J=J)


def default_displacement(model: Model, angle_step: float = DEFAULT_ANGLE_STEP,
                         length_step: float | None = None) -> np.ndarray:
    """Virtual displacement per coordinate: ``angle_step`` (rad) for angles,
    ``length_step`` (m; default angle_step x length scale) for travels."""
    if length_step is None:
        length_step = angle_step * model.length_scale
    return np.where(model.coord_is_angle, angle_step, length_step)


def finite_difference_analogs(model: Model, q, x, *, d=None,
                              layout: ConstraintLayout | None = None) -> np.ndarray:
    """Velocity analogs of the paper's partial systems, by central differences.

    Parameters
    ----------
    q : array_like, shape (n_q,)
    x : array_like, shape (n_x,)
        The solved pose at ``q`` (start of the re-solves).
    d : float or array_like, shape (n_q,), optional
        Virtual displacement per coordinate (rad or m); default 0.1 deg for angles.

    Returns
    -------
    ndarray, shape (n_x, n_q)
    """
    q = np.asarray(q, float)
    d = default_displacement(model) if d is None else np.broadcast_to(
        np.asarray(d, float), (model.n_q,))
    E = np.eye(model.n_q) * d
    qs = np.concatenate([q + E, q - E])  # (2 n_q, n_q): both partial systems at once
    xs = solve_position(model, qs, x, layout=layout, check_singular=False)
    return ((xs[: model.n_q] - xs[model.n_q:]) / (2 * d[:, None])).T
