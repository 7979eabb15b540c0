"""The inertia formulas of the bodies, written once (NumPy, batched): the parallel-axis
theorem, a body's block of the frame mass matrix, and the reduction of a frame mass
matrix and of frame forces to generalized coordinates through the velocity analogs.

A body of mass m and moment of inertia J_c about its centre of mass, whose frame
origin is at the arm ``a`` from that centre (``a`` the centre of mass seen from the
origin, in the ground frame), has about the origin the moment of inertia
J_c + m |a|^2 (:func:`parallel_axis`; :func:`centroidal_inertia` backwards) and in the
frame coordinates (x, y, theta) the mass matrix :func:`body_mass_block`.  With the
pose rates x' = B q' and accelerations x'' = B q'' + b, the equations
M x'' + h = F of the frames become A q'' = f with A = B^T M B (:func:`reduced_mass`)
and f = B^T (F - h - M b) (:func:`reduced_force`).  :func:`analog_mass` gives A from
the centre-of-mass analogs instead.

The compiled twin: :func:`mechdyn.kernels.lagrange_numba._mass_matrix` sums A (and
the bias) body by body in the same way as :func:`analog_mass`, on scalars, and its
``_generalized_forces`` forms B^T F.
"""

from __future__ import annotations

import numpy as np

__all__ = ["parallel_axis", "centroidal_inertia", "body_mass_block", "reduced_mass",
           "reduced_force", "analog_mass"]


def parallel_axis(J_c, m, d) -> np.ndarray:
    """Moment of inertia about a point at the distance vector ``d`` from the centre of
    mass: J_c + m |d|^2 (the parallel-axis theorem).

    Parameters
    ----------
    J_c : float or array_like, shape (...)
        Moments of inertia about the centres of mass, kg m^2.
    m : float or array_like, shape (...)
        Masses, kg.
    d : array_like, shape (..., 2)
        From the centre of mass to the point (or back: only |d| counts), m.

    Returns
    -------
    ndarray, shape (...)
        kg m^2.

    Examples
    --------
    A 2 kg bar of 1 kg m^2 about its centre of mass, about a point 0.5 m away:

    >>> float(parallel_axis(1.0, 2.0, [0.3, 0.4]))
    1.5
    """
    d = np.asarray(d, dtype=float)
    return J_c + m * (d[..., 0] ** 2 + d[..., 1] ** 2)


def centroidal_inertia(J_o, m, d) -> np.ndarray:
    """Moment of inertia about the centre of mass from the one about a point at ``d``
    from it: J_o - m |d|^2 (:func:`parallel_axis` backwards).

    Parameters
    ----------
    J_o : float or array_like, shape (...)
        Moments of inertia about the points, kg m^2.
    m : float or array_like, shape (...)
        Masses, kg.
    d : array_like, shape (..., 2)
        Between the centre of mass and the point, m.

    Returns
    -------
    ndarray, shape (...)
        kg m^2 (negative when J_o is less than m |d|^2: no body has that J_o).

    Examples
    --------
    >>> float(centroidal_inertia(1.5, 2.0, [0.3, 0.4]))
    1.0
    """
    d = np.asarray(d, dtype=float)
    return J_o - m * (d[..., 0] ** 2 + d[..., 1] ** 2)


def body_mass_block(m, J_c, a) -> np.ndarray:
    """A body's block of the frame mass matrix, in its frame coordinates (x, y, theta).

    With the centre of mass at the arm ``a`` from the frame origin, the kinetic energy
    ``1/2 m |v + omega perp(a)|^2 + 1/2 J_c omega^2`` gives
    ``[[m, 0, -m a_y], [0, m, m a_x], [-m a_y, m a_x, J_c + m |a|^2]]``: the coupling
    of the origin's translation and the rotation, zero when the origin is the centre of
    mass, and the moment of inertia about the origin (:func:`parallel_axis`).

    Parameters
    ----------
    m : float or array_like, shape (...)
        Masses, kg.
    J_c : float or array_like, shape (...)
        Moments of inertia about the centres of mass, kg m^2.
    a : array_like, shape (..., 2)
        Arms from the frame origins to the centres of mass, ground frame, m.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        kg, kg m and kg m^2.

    Examples
    --------
    >>> body_mass_block(2.0, 1.0, [0.3, 0.4]).tolist()
    [[2.0, 0.0, -0.8], [0.0, 2.0, 0.6], [-0.8, 0.6, 1.5]]
    """
    a = np.asarray(a, dtype=float)
    m = np.asarray(m, dtype=float)
    out = np.zeros(np.broadcast_shapes(m.shape, np.shape(J_c), a.shape[:-1]) + (3, 3))
    out[..., 0, 0] = m
    out[..., 1, 1] = m
    out[..., 0, 2] = out[..., 2, 0] = -m * a[..., 1]
    out[..., 1, 2] = out[..., 2, 1] = m * a[..., 0]
    out[..., 2, 2] = parallel_axis(J_c, m, a)
    return out


def reduced_mass(M, B) -> np.ndarray:
    """Generalized mass matrix A = B^T M B of the coordinates whose velocity analogs
    (x' = B q') are B.

    Parameters
    ----------
    M : array_like, shape (..., n_x, n_x)
        Mass matrix of the frame coordinates (kg, kg m, kg m^2).
    B : array_like, shape (..., n_x, n)
        Velocity analogs dx/dq.

    Returns
    -------
    ndarray, shape (..., n, n)
        In the units of the coordinates q (kg for a length, kg m^2 for an angle).

    Examples
    --------
    A point mass of 2 kg at the end of a 0.5 m crank (x = 0.5 cos q, y = 0.5 sin q,
    at q = 0: B = [0, 0.5]^T):

    >>> reduced_mass(np.diag([2.0, 2.0]), np.array([[0.0], [0.5]])).tolist()
    [[0.5]]
    """
    B = np.asarray(B, dtype=float)
    return np.swapaxes(B, -1, -2) @ M @ B


def reduced_force(B, F, h=None, M=None, b=None) -> np.ndarray:
    """Generalized force f = B^T (F - h - M b): the frame forces less the inertia
    forces that do not come from q'' (x'' = B q'' + b), projected on the coordinates.

    Parameters
    ----------
    B : array_like, shape (..., n_x, n)
        Velocity analogs dx/dq.
    F : array_like, shape (..., n_x)
        Forces on the frame coordinates (N; N m for an angle).
    h : array_like, shape (..., n_x), optional
        Centripetal inertia forces (same units); none: zero.
    M, b : array_like, shapes (..., n_x, n_x) and (..., n_x), optional
        Frame mass matrix and acceleration bias; none: no M b term.

    Returns
    -------
    ndarray, shape (..., n)
        N for a length coordinate, N m for an angle.

    Examples
    --------
    10 N along y at the crank end of :func:`reduced_mass` give 5 N m; 4 N of
    centripetal force along y take 2 N m of it:

    >>> B = np.array([[0.0], [0.5]])
    >>> reduced_force(B, [0.0, 10.0]).tolist(), reduced_force(B, [0.0, 10.0], [0.0, 4.0]).tolist()
    ([5.0], [3.0])
    """
    B = np.asarray(B, dtype=float)
    v = np.asarray(F, dtype=float)
    if h is not None:
        v = v - h
    if b is not None:
        v = v - M @ b
    Bt = np.swapaxes(B, -1, -2)
    return Bt @ v if v.ndim == 1 else (Bt @ v[..., None])[..., 0]


def analog_mass(vc, w, m, J_c) -> np.ndarray:
    """Generalized mass matrix from the centre-of-mass analogs: A_ij = sum over the
    bodies of m vc_i . vc_j + J_c w_i w_j (equal to :func:`reduced_mass` of the frame
    mass matrix).

    Parameters
    ----------
    vc : array_like, shape (..., n, n_b, 2)
        Velocity analogs of the centres of mass, dr_c/dq_i (m per unit of q_i).
    w : array_like, shape (..., n, n_b)
        Angular analogs dtheta/dq_i.
    m, J_c : array_like, shape (n_b,)
        Masses (kg) and moments of inertia about the centres of mass (kg m^2).

    Returns
    -------
    ndarray, shape (..., n, n)

    Examples
    --------
    The crank of :func:`reduced_mass` as a body: its centre of mass 0.5 m out, 2 kg,
    0.25 kg m^2 about it, turning with q:

    >>> analog_mass([[[0.0, 0.5]]], [[1.0]], [2.0], [0.25]).tolist()
    [[0.75]]
    """
    return (np.einsum("...ibk,...jbk,b->...ij", vc, vc, m)
            + np.einsum("...ib,...jb,b->...ij", w, w, J_c))
