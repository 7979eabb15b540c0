"""Small mechanisms for the dynamics tests (built in Python, data in SI)."""

import numpy as np

from mechdyn import Mechanism


def pendulum(theta0_from_down_deg=170.0, m=2.0, a=0.5, Jc=0.05, g=9.81):
    """Compound pendulum pivoted at its frame origin; centre of mass a along the body x
    axis.  Coordinate ``theta`` = absolute body angle (-90 deg hangs down)."""
    mech = Mechanism("compound pendulum", gravity=(0.0, -g))
    th = np.deg2rad(theta0_from_down_deg) - np.pi / 2
    mech.add_body("bar", mass=m, inertia=Jc, com=(a, 0.0), pose=(0.0, 0.0, th))
    mech.add_revolute("O", "ground", "bar")
    mech.add_coordinate("theta", kind="angle", body="bar")
    return mech


def _circle_intersection(P, r1, Q, r2, sign=1.0):
    d = np.linalg.norm(Q - P)
    a = (r1**2 - r2**2 + d**2) / (2 * d)
    h = np.sqrt(r1**2 - a**2)
    e = (Q - P) / d
    return P + a * e + sign * h * np.array([-e[1], e[0]])


def four_bar(coordinate="phi", phi0=np.pi / 2, gravity=(0.0, -9.81)):
    """Crank-rocker four-bar: O-A 0.1 m, A-B 0.3 m, C-B 0.25 m, O-C 0.3 m.

    Coordinate ``phi`` (crank angle) or ``psi`` (rocker angle), both absolute.
    """
    l1, l2, l3 = 0.1, 0.3, 0.25
    O, C = np.zeros(2), np.array([0.3, 0.0])
    A = l1 * np.array([np.cos(phi0), np.sin(phi0)])
    B = _circle_intersection(A, l2, C, l3)
    mech = Mechanism("four-bar", gravity=gravity)
    mech.add_ground({"O": tuple(O), "C": tuple(C)})
    mech.add_body("crank", mass=0.5, inertia=0.002, com=(0.05, 0.0), points={"A": (l1, 0.0)},
                  pose=(0.0, 0.0, phi0))
    mech.add_body("coupler", mass=1.0, inertia=0.01, com=(0.15, 0.01), points={"B": (l2, 0.0)},
                  pose=(A[0], A[1], np.arctan2(*(B - A)[::-1])))
    mech.add_body("rocker", mass=1.0, inertia=0.008, com=(0.125, 0.0), points={"B": (l3, 0.0)},
                  pose=(C[0], C[1], np.arctan2(*(B - C)[::-1])))
    mech.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    mech.add_revolute("A", "crank", "coupler", "A", (0.0, 0.0))
    mech.add_revolute("B", "coupler", "rocker", "B", "B")
    mech.add_revolute("C", "ground", "rocker", "C", (0.0, 0.0))
    body = "crank" if coordinate == "phi" else "rocker"
    mech.add_coordinate(coordinate, kind="angle", body=body)
    return mech


def slider_crank(coordinate="phi", phi0=0.6):
    """Offset slider-crank: crank 0.08 m, rod 0.25 m, slider on the x axis 0.02 m below O.

    Coordinate ``phi`` (relative angle of joint O) or ``s`` (travel of the slider).
    """
    r, l, e = 0.08, 0.25, -0.02
    A = r * np.array([np.cos(phi0), np.sin(phi0)])
    xb = A[0] + np.sqrt(l**2 - (e - A[1]) ** 2)
    mech = Mechanism("slider-crank", gravity=(0.0, -9.81))
    mech.add_ground({"O": (0.0, 0.0), "guide": (0.0, e)})
    mech.add_body("crank", mass=0.8, inertia=0.001, com=(0.03, 0.005), points={"A": (r, 0.0)},
                  pose=(0.0, 0.0, phi0))
    mech.add_body("rod", mass=1.2, inertia=0.008, com=(0.1, 0.0), points={"B": (l, 0.0)},
                  pose=(A[0], A[1], np.arctan2(e - A[1], xb - A[0])))
    mech.add_body("slider", mass=2.0, inertia=0.0, pose=(xb, e, 0.0))
    mech.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    mech.add_revolute("A", "crank", "rod", "A", (0.0, 0.0))
    mech.add_revolute("B", "rod", "slider", "B", (0.0, 0.0))
    mech.add_prismatic("guide", "ground", "slider", "guide", (1.0, 0.0), (0.0, 0.0))
    if coordinate == "phi":
        mech.add_coordinate("phi", kind="relative_angle", joint="O")
    else:
        mech.add_coordinate("s", kind="travel", joint="guide")
    return mech


def parallelogram(phi0=np.pi / 2, g=9.81, m=1.0, l=1.0):
    """Parallelogram four-bar: ground pivots O = (0, 0) and C = (l, 0), crank O-A, coupler
    A-B and rocker C-B all of length l; uniform rods of mass m (centre of mass at
    mid-length, J_c = m l^2 / 12).  Coordinate ``phi`` = absolute crank angle; sketched
    on the parallelogram branch (the rocker parallel to the crank, the coupler level).
    Flat (bifurcation) positions at phi = 0 and pi."""
    mech = Mechanism("parallelogram four-bar", gravity=(0.0, -g))
    mech.add_ground({"O": (0.0, 0.0), "C": (l, 0.0)})
    A = l * np.array([np.cos(phi0), np.sin(phi0)])
    for name, pose in (("crank", (0.0, 0.0, phi0)), ("coupler", (A[0], A[1], 0.0)),
                       ("rocker", (l, 0.0, phi0))):
        mech.add_body(name, mass=m, inertia=m * l * l / 12, com=(l / 2, 0.0),
                      points={"E": (l, 0.0)}, pose=pose)
    mech.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    mech.add_revolute("A", "crank", "coupler", "E", (0.0, 0.0))
    mech.add_revolute("B", "coupler", "rocker", "E", "E")
    mech.add_revolute("C", "ground", "rocker", "C", (0.0, 0.0))
    mech.add_coordinate("phi", kind="angle", body="crank")
    return mech
