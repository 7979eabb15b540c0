"""Slider-crank kinematics from the sweep against the closed form.

For an in-line slider-crank (crank r, rod l, slider on the x axis through the
crank centre) the slider position is x = r cos(phi) + sqrt(l^2 - r^2 sin^2 phi);
its derivatives are differentiated by hand below, independently of mechdyn.
"""

import numpy as np
import pytest

from mechdyn import Mechanism
from mechdyn.kinematics.sweep import sweep


def slider_crank(r, l, phi0=0.7, e=0.0):
    """Crank about the origin, rod A-B, slider B on the line y = e (offset e)."""
    m = Mechanism("slider-crank")
    A = r * np.array([np.cos(phi0), np.sin(phi0)])
    xB = A[0] + np.sqrt(l**2 - (A[1] - e) ** 2)
    beta = np.arctan2(e - A[1], xB - A[0])
    m.add_ground(points={"O": (0.0, 0.0), "G": (0.0, e)})
    m.add_body("crank", mass=2.0, inertia=0.01, com=(0.3 * r, 0.0), points={"A": (r, 0.0)},
               pose=(0.0, 0.0, phi0))
    m.add_body("rod", mass=1.0, inertia=0.004, com=(0.3 * l, 0.0),
               points={"A": (0.0, 0.0), "B": (l, 0.0)}, pose=(A[0], A[1], beta))
    m.add_body("slider", mass=0.8, points={"B": (0.0, 0.0)}, pose=(xB, e, 0.0))
    m.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    m.add_revolute("A", "crank", "rod", "A", "A")
    m.add_revolute("B", "rod", "slider", "B", "B")
    m.add_prismatic("P", "ground", "slider", "G", (1.0, 0.0), (0.0, 0.0))
    m.add_coordinate("phi", "angle", body="crank")
    return m


def closed_form(r, l, phi):
    """x, dx/dphi, d2x/dphi2 of the in-line slider-crank."""
    s = np.sqrt(l**2 - (r * np.sin(phi)) ** 2)
    f = r**2 * np.sin(phi) * np.cos(phi)
    x = r * np.cos(phi) + s
    dx = -r * np.sin(phi) - f / s
    ddx = -r * np.cos(phi) - r**2 * np.cos(2 * phi) / s - f**2 / s**3
    return x, dx, ddx


@pytest.mark.parametrize("r, l, omega", [(0.015, 0.040, 1.0), (0.05, 0.16, 157.07963),
                                         (0.1, 0.12, 20.0)])
def test_slider_position_velocity_acceleration_match_closed_form(r, l, omega):
    sw = sweep(slider_crank(r, l), values=np.linspace(0.0, 2 * np.pi, 721), speed=omega)
    assert sw.status == "success" and len(sw) == 721
    phi = sw.values
    x, dx, ddx = closed_form(r, l, phi)
    rB, vB, aB = sw.point("slider", "B")
    for got, want in ((rB[:, 0], x), (vB[:, 0], dx * omega), (aB[:, 0], ddx * omega**2)):
        assert np.max(np.abs(got - want)) <= 1e-10 * np.max(np.abs(want))
    # the slider stays on its line and does not turn
    assert np.max(np.abs(rB[:, 1])) < 1e-13
    assert np.max(np.abs(sw.angular("slider")[1])) < 1e-12
    # crank angle and rate are the ones imposed
    th, om, al = sw.angular("crank")
    assert np.allclose(th, phi, rtol=0, atol=1e-14)
    assert np.allclose(om, omega, rtol=1e-14) and np.max(np.abs(al)) < 1e-9 * omega**2


def test_rod_angle_matches_closed_form():
    r, l = 0.05, 0.16
    sw = sweep(slider_crank(r, l), values=np.linspace(0.0, 2 * np.pi, 361))
    beta = -np.arcsin(r * np.sin(sw.values) / l)  # rod angle from the crank-pin side
    dbeta = -r * np.cos(sw.values) / np.sqrt(l**2 - (r * np.sin(sw.values)) ** 2)
    th, om, _ = sw.angular("rod")
    assert np.max(np.abs(th - beta)) < 1e-12
    assert np.max(np.abs(om - dbeta)) < 1e-10 * np.max(np.abs(dbeta))


def test_offset_slider_crank_velocity_analog():
    # x = r cos phi + sqrt(l^2 - (r sin phi - e)^2); dx/dphi by hand
    r, l, e = 0.04, 0.15, 0.02
    sw = sweep(slider_crank(r, l, e=e), values=np.linspace(0.0, 2 * np.pi, 361))
    phi = sw.values
    s = np.sqrt(l**2 - (r * np.sin(phi) - e) ** 2)
    x = r * np.cos(phi) + s
    dx = -r * np.sin(phi) - (r * np.sin(phi) - e) * r * np.cos(phi) / s
    rB = sw.point("slider", "B")[0]
    dr = sw.point_analogs("slider", "B")
    assert np.max(np.abs(rB[:, 0] - x)) < 1e-13
    assert np.max(np.abs(dr[:, 0, 0] - dx)) <= 1e-10 * np.max(np.abs(dx))
