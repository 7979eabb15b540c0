"""Andrews' squeezing mechanism (the "seven-body mechanism") and its Test Set oracles.

The data and the reference solution are those of the Test Set for IVP Solvers
(F. Mazzia, C. Magherini, *Test Set for Initial Value Problem Solvers*,
release 2.4, University of Bari, 2008, problem ``andrews``), which takes the
problem from E. Hairer, G. Wanner, *Solving Ordinary Differential Equations
II*, 2nd ed., Springer 1996, section VII.7 ("Multibody systems", the
seven-body mechanism of Schiehlen / Manning and Andrews).

The model is the bundled ``andrews_squeezer.toml`` (:func:`build` loads it); this
module holds the Test Set's data, reference solution, kinematics and mass matrix,
which the tests compare it with.

The Test Set describes the mechanism by seven angles q = (beta, Theta, gamma,
Phi, delta, Omega, epsilon), some of them *relative* (Theta, Phi, Omega).
mechdyn uses the absolute pose of each body; the body frames here are chosen
so that the body angles are simple sums of the Test Set's angles:

==========  ======  ===========================  =====================================
body        origin  frame angle                  points (body frame)
==========  ======  ===========================  =====================================
crank (1)   O       beta                         F = (rr, 0), com = (ra, 0)
rod (2)     F       beta + Theta                 E = (-d, 0), com = (-da, 0)
triangle(3) B       gamma                        E = (0, -ss), D = (sd, -sc), com = (sb, -sa)
link4 (4)   G       Phi + delta                  E = (0, -e), com = (0, -(e - ea))
link5 (5)   A       delta                        G = (zt, 0), com = (ta, tb)
link6 (6)   H       Omega + epsilon              E = (zf, 0), com = (zf - fa, 0)
link7 (7)   A       epsilon                      H = (0, -u), com = (ub, -ua)
==========  ======  ===========================  =====================================

The ground points are O = (0, 0), A = (xa, ya), B = (xb, yb), C = (xc, yc).  The
joints, the loads (spring D-C, torque ``mom`` on the crank; no gravity) and the
assumed directions of the centres of mass of links 5 and 7 (the Test Set gives
only their distances from A) are set out in the model file.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..mechanism import Mechanism
from . import load

__all__ = ["PARAMS", "Q0", "ANGLE_NAMES", "REFERENCE_T003", "REFERENCE_T003_RATES", "build",
           "test_set_angles", "test_set_mass_matrix", "sketch_poses"]

#: Test Set parameters, SI (kg, kg m^2, m, N/m, N m)
PARAMS: dict[str, float] = {
    "m1": 0.04325, "m2": 0.00365, "m3": 0.02373, "m4": 0.00706,
    "m5": 0.07050, "m6": 0.00706, "m7": 0.05498,
    "I1": 2.194e-6, "I2": 4.410e-7, "I3": 5.255e-6, "I4": 5.667e-7,
    "I5": 1.169e-5, "I6": 5.667e-7, "I7": 1.912e-5,
    "xa": -0.06934, "ya": -0.00227, "xb": -0.03635, "yb": 0.03273,
    "xc": 0.014, "yc": 0.072,
    "d": 0.028, "da": 0.0115, "e": 0.02, "ea": 0.01421, "rr": 0.007, "ra": 0.00092,
    "ss": 0.035, "sa": 0.01874, "sb": 0.01043, "sc": 0.018, "sd": 0.02,
    "ta": 0.02308, "tb": 0.00916, "u": 0.04, "ua": 0.01228, "ub": 0.00449,
    "zf": 0.02, "zt": 0.04, "fa": 0.01421,
    "c0": 4530.0, "l0": 0.07785, "mom": 0.033,
}

#: order of the Test Set's angles
ANGLE_NAMES = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")

#: consistent initial angles of the Test Set, rad
Q0: dict[str, float] = {
    "beta": -0.0617138900142764496358948458001,
    "Theta": 0.0,
    "gamma": 0.455279819163070380255912382449,
    "Phi": 0.222668390165885884674473185609,
    "delta": 0.487364979543842550225598953530,
    "Omega": -0.222668390165885884674473185609,
    "epsilon": 1.23054744454982119249735015568,
}

#: the Test Set's reference solution at t = 0.03 s (angles, rad), started at rest from Q0
REFERENCE_T003: dict[str, float] = {
    "beta": 15.81077119629904,
    "Theta": -15.75637105984298,
    "gamma": 0.04082224013073101,
    "Phi": -0.5347301163226948,
    "delta": 0.5244099658805304,
    "Omega": 0.5347301163226948,
    "epsilon": 1.048080741042263,
}

#: ... and the rates of the first two angles at t = 0.03 s, rad/s
REFERENCE_T003_RATES: dict[str, float] = {
    "beta": 1139.920302151208,
    "Theta": -1424.379294994111,
}

#: the frame angle of each body (the table above) as its own Test Set angle plus, for a
#: relative angle, the absolute angle it is measured from
_FRAME_ANGLES = {"crank": ("beta",), "rod": ("Theta", "beta"), "triangle": ("gamma",),
                 "link4": ("Phi", "delta"), "link5": ("delta",), "link6": ("Omega", "epsilon"),
                 "link7": ("epsilon",)}


def sketch_poses(angles: Mapping[str, float] | None = None) -> dict[str, tuple[float, ...]]:
    """Body poses (x, y, theta) in m and rad for given Test Set angles (default ``Q0``).

    The poses follow the open tree of the Test Set's kinematics (crank, rod,
    triangle, link5 -> link4, link7 -> link6); they close at E only for
    consistent angles.
    """
    p = PARAMS
    a = dict(Q0 if angles is None else angles)
    be, de, ep = a["beta"], a["delta"], a["epsilon"]
    A = (p["xa"], p["ya"])
    origins = {"crank": (0.0, 0.0), "rod": (p["rr"] * math.cos(be), p["rr"] * math.sin(be)),
               "triangle": (p["xb"], p["yb"]), "link5": A, "link7": A,
               "link4": (p["xa"] + p["zt"] * math.cos(de), p["ya"] + p["zt"] * math.sin(de)),
               "link6": (p["xa"] + p["u"] * math.sin(ep), p["ya"] - p["u"] * math.cos(ep))}
    return {b: (*origins[b], sum(a[n] for n in names)) for b, names in _FRAME_ANGLES.items()}


def build(*, loads: bool = True) -> Mechanism:
    """Andrews' squeezing mechanism as a :class:`~mechdyn.mechanism.Mechanism`.

    Parameters
    ----------
    loads : bool
        Keep the spring (D-C) and the driving torque on the crank.

    Returns
    -------
    Mechanism
        The bundled ``andrews_squeezer`` example: seven bodies, ten revolutes, one
        coordinate ``beta`` (absolute crank angle, rad), sketched at the Test Set's
        consistent angles ``Q0``; no gravity.  ``extras["initial"]`` holds
        beta = Q0["beta"] and rate 0.
    """
    m = load("andrews_squeezer")
    if not loads:
        m.loads.clear()
    return m


def test_set_angles(model, x) -> dict[str, np.ndarray | float]:
    """The Test Set's seven angles from mechdyn body poses.

    Parameters
    ----------
    model : mechdyn.model.Model
        A compiled model of this mechanism (``build().compile()`` or the
        ``andrews_squeezer.toml`` example).
    x : array_like, shape (..., n_x)
        Body poses.

    Returns
    -------
    dict
        ``beta, Theta, gamma, Phi, delta, Omega, epsilon`` in rad (arrays of the
        leading shape of ``x``).  The relative angles are plain differences of
        the body angles, so they follow the body angles without wrapping.
    """
    x = np.asarray(x, dtype=float)
    th = {b: x[..., 3 * model.body_index(b) + 2] for b in _FRAME_ANGLES}
    absolute = {names[0]: th[b] for b, names in _FRAME_ANGLES.items() if len(names) == 1}
    out = {own: th[b] - sum(absolute[n] for n in base)
           for b, (own, *base) in _FRAME_ANGLES.items()}
    if x.ndim == 1:
        return {k: float(v) for k, v in out.items()}
    return out


def test_set_mass_matrix(angles: Mapping[str, float] | np.ndarray) -> np.ndarray:
    """The Test Set's mass matrix M(q) of the seven angles (andrews.f), shape (7, 7), SI.

    Parameters
    ----------
    angles : mapping or array_like, shape (7,)
        ``beta, Theta, gamma, Phi, delta, Omega, epsilon`` in rad (by name or in
        that order).

    Returns
    -------
    ndarray, shape (7, 7)
        kg m^2; the kinetic energy is T = 1/2 qdot^T M qdot.
    """
    if isinstance(angles, Mapping):
        q = [float(angles[n]) for n in ANGLE_NAMES]
    else:
        q = [float(v) for v in np.asarray(angles, dtype=float).reshape(7)]
    _, th, _, ph, _, om, _ = q
    p = PARAMS
    m1, m2, m3, m4, m5, m6, m7 = (p[f"m{k}"] for k in range(1, 8))
    i1, i2, i3, i4, i5, i6, i7 = (p[f"I{k}"] for k in range(1, 8))
    rr, ra, da = p["rr"], p["ra"], p["da"]
    e_ea = p["e"] - p["ea"]
    zf_fa = p["zf"] - p["fa"]
    zt, u = p["zt"], p["u"]
    M = np.zeros((7, 7))
    M[0, 0] = m1 * ra**2 + m2 * (rr**2 - 2 * da * rr * math.cos(th) + da**2) + i1 + i2
    M[1, 0] = M[0, 1] = m2 * (da**2 - da * rr * math.cos(th)) + i2
    M[1, 1] = m2 * da**2 + i2
    M[2, 2] = m3 * (p["sa"] ** 2 + p["sb"] ** 2) + i3
    M[3, 3] = m4 * e_ea**2 + i4
    M[4, 3] = M[3, 4] = m4 * (e_ea**2 + zt * e_ea * math.sin(ph)) + i4
    M[4, 4] = (m4 * (zt**2 + 2 * zt * e_ea * math.sin(ph) + e_ea**2)
               + m5 * (p["ta"] ** 2 + p["tb"] ** 2) + i4 + i5)
    M[5, 5] = m6 * zf_fa**2 + i6
    M[6, 5] = M[5, 6] = m6 * (zf_fa**2 - u * zf_fa * math.sin(om)) + i6
    M[6, 6] = (m6 * (zf_fa**2 - 2 * u * zf_fa * math.sin(om) + u**2)
               + m7 * (p["ua"] ** 2 + p["ub"] ** 2) + i6 + i7)
    return M
