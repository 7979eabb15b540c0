"""Velocity analogs, residuals, dead centres and transmission angles: independent checks.

* exact analogs B = dx/dq against the paper's central differences (partial
  systems): the difference must fall as d^2 (measured order ~ 2);
* the constraint equations hold to round-off at every position of a sweep;
* dead centres of an offset slider-crank where crank and rod line up
  (closed form), and the stroke between them;
* the transmission angle of a four-bar against the law of cosines.
"""

import numpy as np
import pytest

from mechdyn import Mechanism
from mechdyn.kinematics import finite_difference_analogs, residual
from mechdyn.kinematics.sweep import sweep


def six_bar():
    """A toggle press: crank-rocker four-bar A-B-D-C plus dyad E-F and a vertical slider."""
    m = Mechanism("six-bar")
    r, lBD, lCD, lEF, xF = 0.08, 0.30, 0.20, 0.30, 0.20
    C = np.array([0.32, 0.0])
    phi = 1.0
    B = r * np.array([np.cos(phi), np.sin(phi)])
    e = np.linalg.norm(C - B)
    u = (C - B) / e
    along = (lBD**2 - lCD**2 + e**2) / (2 * e)
    D = B + along * u + np.sqrt(lBD**2 - along**2) * np.array([-u[1], u[0]])
    thBD = np.arctan2(D[1] - B[1], D[0] - B[0])
    E_loc = np.array([0.15, -0.12])
    E = B + np.array([np.cos(thBD) * E_loc[0] - np.sin(thBD) * E_loc[1],
                      np.sin(thBD) * E_loc[0] + np.cos(thBD) * E_loc[1]])
    F = np.array([xF, E[1] - np.sqrt(lEF**2 - (xF - E[0]) ** 2)])
    m.add_ground(points={"A": (0.0, 0.0), "C": tuple(C), "S": (xF, 0.0)})
    m.add_body("crank", mass=2, inertia=0.01, com=(r / 2, 0), points={"B": (r, 0)},
               pose=(0, 0, phi))
    m.add_body("toggle", mass=5, inertia=0.05, com=(0.12, -0.03),
               points={"B": (0, 0), "D": (lBD, 0), "E": tuple(E_loc)},
               pose=(B[0], B[1], thBD))
    m.add_body("rocker", mass=2, inertia=0.01, com=(lCD / 2, 0), points={"D": (lCD, 0)},
               pose=(C[0], C[1], np.arctan2(D[1] - C[1], D[0] - C[0])))
    m.add_body("link", mass=2, inertia=0.01, com=(lEF / 2, 0), points={"F": (lEF, 0)},
               pose=(E[0], E[1], np.arctan2(F[1] - E[1], F[0] - E[0])))
    m.add_body("ram", mass=20, pose=(F[0], F[1], 0.0))
    m.add_revolute("A", "ground", "crank", "A", (0, 0))
    m.add_revolute("B", "crank", "toggle", "B", "B")
    m.add_revolute("C", "ground", "rocker", "C", (0, 0))
    m.add_revolute("D", "rocker", "toggle", "D", "D")
    m.add_revolute("E", "toggle", "link", "E", (0, 0))
    m.add_revolute("F", "link", "ram", "F", (0, 0))
    m.add_prismatic("slide", "ground", "ram", "S", (0.0, 1.0), (0.0, 0.0))
    m.add_coordinate("phi", "angle", body="crank")
    return m


@pytest.fixture(scope="module")
def press():
    model = six_bar().compile()
    return model, sweep(model, values=1.0 + np.linspace(0, 2 * np.pi, 73))


def test_central_difference_analogs_converge_to_exact_ones_at_second_order(press):
    model, sw = press
    ds = np.array([0.04, 0.02, 0.01, 0.005])
    for i in (3, 30, 55):
        errs = [np.max(np.abs(finite_difference_analogs(model, sw.q[i], sw.x[i], d=d)
                              - sw.B[i])) for d in ds]
        slope = np.polyfit(np.log(ds), np.log(errs), 1)[0]
        assert 1.9 < slope < 2.1, (i, errs)


def test_constraints_hold_to_round_off_at_every_position(press):
    model, sw = press
    r = residual(model, sw.x)
    assert np.max(np.abs(r)) < 1e-12  # m (and rad for angle rows)
    # and the coordinates are the requested ones
    assert np.max(np.abs(sw.x[:, 2] - sw.values)) < 1e-14


def test_velocities_satisfy_the_velocity_constraints(press):
    # d/dt Phi = Phi_x xdot = 0 at every position, checked with constraints.jacobian
    from mechdyn.kinematics import jacobian

    model, sw = press
    J = jacobian(model, sw.x)
    assert np.max(np.abs(np.einsum("nij,nj->ni", J, sw.xdot))) < 1e-13


def offset_slider_crank(r, l, e, phi0=0.8):
    m = Mechanism("offset slider-crank")
    A = r * np.array([np.cos(phi0), np.sin(phi0)])
    xB = A[0] + np.sqrt(l**2 - (A[1] - e) ** 2)
    m.add_ground(points={"O": (0.0, 0.0), "G": (0.0, e)})
    m.add_body("crank", points={"A": (r, 0.0)}, pose=(0.0, 0.0, phi0))
    m.add_body("rod", points={"B": (l, 0.0)},
               pose=(A[0], A[1], np.arctan2(e - A[1], xB - A[0])))
    m.add_body("slider", pose=(xB, e, 0.0))
    m.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    m.add_revolute("A", "crank", "rod", "A", (0.0, 0.0))
    m.add_revolute("B", "rod", "slider", "B", (0.0, 0.0))
    m.add_prismatic("cyl", "ground", "slider", "G", (1.0, 0.0), (0.0, 0.0))
    m.add_coordinate("phi", "angle", body="crank")
    return m


@pytest.mark.parametrize("e", [0.0, 0.02])
def test_dead_centres_of_a_slider_crank_where_crank_and_rod_line_up(e):
    r, l = 0.05, 0.16
    sw = sweep(offset_slider_crank(r, l, e), values=np.linspace(-1.0, -1.0 + 2 * np.pi, 181))
    summ = sw.summary()
    # TDC: crank and rod stretched out, |OB| = l + r; BDC: folded, |OB| = l - r
    x_t = np.sqrt((l + r) ** 2 - e**2)
    x_b = np.sqrt((l - r) ** 2 - e**2)
    phi_t = np.arctan2(e, x_t)
    phi_b = np.arctan2(-e, -x_b) % (2 * np.pi)
    dc = {d.label: d for d in summ.dead_centres}
    assert set(dc) == {"TDC", "BDC"} and len(summ.dead_centres) == 2
    assert abs(dc["TDC"].at - phi_t) < 1e-10
    assert abs(dc["BDC"].at - phi_b) < 1e-10
    assert abs(dc["TDC"].travel - x_t) < 1e-13 and abs(dc["BDC"].travel - x_b) < 1e-13
    assert abs(summ.strokes["cyl"] - (x_t - x_b)) < 1e-13
    # TDC is where x is largest, as sampled
    rB = sw.point("slider", (0.0, 0.0))[0]
    assert dc["TDC"].travel >= rB[:, 0].max() - 1e-15


A_, B_, C_, D_ = 0.02, 0.07, 0.05, 0.06  # crank, coupler, rocker, frame (crank-rocker)


def four_bar(phi0=1.0):
    m = Mechanism("four-bar")
    B = A_ * np.array([np.cos(phi0), np.sin(phi0)])
    e = np.hypot(D_ - B[0], B[1])
    u = np.array([D_ - B[0], -B[1]]) / e
    along = (B_**2 - C_**2 + e**2) / (2 * e)
    C = B + along * u + np.sqrt(B_**2 - along**2) * np.array([-u[1], u[0]])
    m.add_body("crank", points={"B": (A_, 0.0)}, pose=(0.0, 0.0, phi0))
    m.add_body("coupler", points={"C": (B_, 0.0)},
               pose=(B[0], B[1], np.arctan2(C[1] - B[1], C[0] - B[0])))
    m.add_body("rocker", points={"C": (C_, 0.0)}, pose=(D_, 0.0, np.arctan2(C[1], C[0] - D_)))
    m.add_revolute("A", "ground", "crank")
    m.add_revolute("B", "crank", "coupler", "B", (0.0, 0.0))
    m.add_revolute("C", "coupler", "rocker", "C", "C")
    m.add_revolute("D", "ground", "rocker", (D_, 0.0), (0.0, 0.0))
    m.add_coordinate("phi", "angle", body="crank")
    return m


def test_transmission_angle_follows_the_law_of_cosines():
    phi = np.linspace(0, 2 * np.pi, 361)
    sw = sweep(four_bar(), values=phi)
    t = sw.summary().transmission
    assert len(t) == 1
    # angle at the coupler-rocker joint C between C->B and C->D:
    # |BD|^2 = a^2 + d^2 - 2 a d cos(phi);  cos mu = (b^2 + c^2 - |BD|^2) / (2 b c)
    bd2 = A_**2 + D_**2 - 2 * A_ * D_ * np.cos(phi)
    mu = np.arccos((B_**2 + C_**2 - bd2) / (2 * B_ * C_))
    assert abs(t[0].min - mu.min()) < 1e-12 and abs(t[0].max - mu.max()) < 1e-12
    assert abs(t[0].min_at - 0.0) < 1e-12 and abs(t[0].max_at - np.pi) < 1e-12
    mu_min = np.arccos((B_**2 + C_**2 - (D_ - A_) ** 2) / (2 * B_ * C_))
    assert abs(t[0].min - mu_min) < 1e-12
