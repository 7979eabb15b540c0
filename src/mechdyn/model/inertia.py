"""Inertia forces of the body frames: the frame mass matrix M_x and the inertia
forces ``M_x xddot`` plus the centripetal terms, batched over poses."""

from __future__ import annotations

import numpy as np

from ..kernels.inertia import body_mass_block
from ..kernels.planar import cross, perp
from . import Model
from .forces import com_arms

__all__ = ["frame_mass_matrix", "inertia_forces", "mass_matrix_x", "drive_inertia"]


def frame_mass_matrix(model: Model, x) -> np.ndarray:
    """Mass matrix M_x of the body-frame coordinates, shape (..., n_x, n_x).

    With the centre of mass at ``a = A(theta) com`` from the frame origin, the
    kinetic energy ``1/2 m |v + omega perp(a)|^2 + 1/2 J_c omega^2`` gives, per
    body, the block ``[[m, 0, -m a_y], [0, m, m a_x], [-m a_y, m a_x, J_c + m |a|^2]]``
    (kg, kg m, kg m^2; :func:`mechdyn.kernels.inertia.body_mass_block`).  The inertia
    forces are ``M_x xddot`` plus the centripetal force ``-m omega^2 a`` (see
    :func:`inertia_forces`).
    """
    x = np.asarray(x, dtype=float)
    blocks = body_mass_block(model.mass, model.inertia, com_arms(model, x))  # (..., nb, 3, 3)
    M = np.zeros(x.shape[:-1] + (model.n_x, model.n_x))
    for b in range(model.n_bodies):
        M[..., 3 * b:3 * b + 3, 3 * b:3 * b + 3] = blocks[..., b, :, :]
    return M


def inertia_forces(model: Model, x, xdot, xddot) -> np.ndarray:
    """Inertia forces conjugate to the body-frame poses, shape (..., n_x).

    Per body: ``m a_c`` (N) and ``J_c alpha + a x (m a_c)`` (N m, about the
    frame origin), with ``a_c = rddot + alpha perp(a) - omega^2 a`` the
    acceleration of the centre of mass.  Equals ``M_x xddot - m omega^2 a``.

    Parameters
    ----------
    x, xdot, xddot : array_like, shape (..., n_x)
        Poses (m, rad), their rates and accelerations.
    """
    x = np.asarray(x, dtype=float)
    nb = model.n_bodies
    batch = x.shape[:-1]
    V = np.asarray(xdot, dtype=float).reshape(batch + (nb, 3))
    W = np.asarray(xddot, dtype=float).reshape(batch + (nb, 3))
    a = com_arms(model, x)
    ac = W[..., :2] + W[..., 2, None] * perp(a) - (V[..., 2] ** 2)[..., None] * a
    f = model.mass[:, None] * ac
    mom = model.inertia * W[..., 2] + cross(a, f)
    return np.concatenate([f, mom[..., None]], axis=-1).reshape(batch + (model.n_x,))


def mass_matrix_x(model: Model, x, xdot=None):
    """M_x (n_x, n_x) of the body-frame coordinates at one pose, and the centripetal
    term h (n_x,) (zero without ``xdot``): M_x xddot + h are the inertia forces
    (:func:`inertia_forces`; force, N, and moment about the frame origin, N m)."""
    M = frame_mass_matrix(model, x)
    if xdot is None:
        return M, np.zeros(model.n_x)
    return M, inertia_forces(model, x, xdot, np.zeros(model.n_x))


def drive_inertia(model: Model) -> np.ndarray:
    """Inertia the drives add to their own coordinates (rotor and gears reduced to the
    coordinate, ``extra_inertia()`` of a drive's torque object), shape (n_q,), kg m^2."""
    out = np.zeros(model.n_q)
    for dr in model.mechanism.drives:
        fn = getattr(dr.torque, "extra_inertia", None)
        if fn is not None and dr.coordinate in model.coordinate_names:
            out[model.coordinate_index(dr.coordinate)] += float(fn())
    return out
