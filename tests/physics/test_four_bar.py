"""Four-bar angles from the sweep against Freudenstein's closed form, on both branches.

Ground pivots A = (0, 0) (crank, length a) and D = (d, 0) (rocker, length c),
coupler b.  Freudenstein: K1 cos psi - K2 cos phi + K3 = cos(phi - psi) with
K1 = d/a, K2 = d/c, K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c); with t = tan(psi/2)
it becomes a quadratic whose two roots are the two assembly branches.
"""

import numpy as np
import pytest

from mechdyn import Mechanism
from mechdyn.kinematics.sweep import four_bar_loops, sweep

A_, B_, C_, D_ = 0.02, 0.07, 0.05, 0.06  # Grashof crank-rocker: 0.02 + 0.07 <= 0.05 + 0.06


def four_bar(a=A_, b=B_, c=C_, d=D_, phi0=1.0, crossed=False, drive="crank"):
    """Crank-rocker with the coupler point C above (open) or below (crossed) line B-D."""
    m = Mechanism("four-bar")
    B = a * np.array([np.cos(phi0), np.sin(phi0)])
    D = np.array([d, 0.0])
    e = np.linalg.norm(D - B)
    u = (D - B) / e
    along = (b**2 - c**2 + e**2) / (2 * e)
    h = np.sqrt(b**2 - along**2) * (-1.0 if crossed else 1.0)
    C = B + along * u + h * np.array([-u[1], u[0]])
    m.add_ground(points={"A": (0.0, 0.0), "D": (d, 0.0)})
    m.add_body("crank", mass=0.2, inertia=1e-4, com=(a / 2, 0.0), points={"B": (a, 0.0)},
               pose=(0.0, 0.0, phi0))
    m.add_body("coupler", mass=0.5, inertia=6e-4, com=(b / 2, 0.0),
               points={"B": (0.0, 0.0), "C": (b, 0.0)},
               pose=(B[0], B[1], np.arctan2(C[1] - B[1], C[0] - B[0])))
    m.add_body("rocker", mass=0.3, inertia=2e-4, com=(c / 2, 0.0), points={"C": (c, 0.0)},
               pose=(d, 0.0, np.arctan2(C[1], C[0] - d)))
    m.add_revolute("A", "ground", "crank", "A", (0.0, 0.0))
    m.add_revolute("B", "crank", "coupler", "B", "B")
    m.add_revolute("C", "coupler", "rocker", "C", "C")
    m.add_revolute("D", "ground", "rocker", "D", (0.0, 0.0))
    if drive == "crank":
        m.add_coordinate("phi", "angle", body="crank")
    else:
        m.add_coordinate("psi", "angle", body="rocker")
    return m


def freudenstein(phi, a=A_, b=B_, c=C_, d=D_):
    """Both roots (psi_plus, psi_minus) of Freudenstein's equation."""
    K1, K2, K3 = d / a, d / c, (a**2 - b**2 + c**2 + d**2) / (2 * a * c)
    A = np.cos(phi) - K1 - K2 * np.cos(phi) + K3
    B = -2 * np.sin(phi)
    C = K1 - (K2 + 1) * np.cos(phi) + K3
    root = np.sqrt(B**2 - 4 * A * C)
    return 2 * np.arctan2(-B + root, 2 * A), 2 * np.arctan2(-B - root, 2 * A)


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def test_freudenstein_residual_is_zero_for_both_roots():
    # the oracle itself: both roots satisfy the equation
    phi = np.linspace(0, 2 * np.pi, 50)
    K1, K2, K3 = D_ / A_, D_ / C_, (A_**2 - B_**2 + C_**2 + D_**2) / (2 * A_ * C_)
    for psi in freudenstein(phi):
        assert np.max(np.abs(K1 * np.cos(psi) - K2 * np.cos(phi) + K3
                             - np.cos(phi - psi))) < 1e-12


@pytest.mark.parametrize("crossed", [False, True], ids=["open", "crossed"])
def test_four_bar_angles_match_freudenstein_on_the_sketched_branch(crossed):
    sw = sweep(four_bar(crossed=crossed), values=1.0 + np.linspace(0, 2 * np.pi, 721))
    assert sw.status == "success" and len(sw) == 721
    phi = sw.values
    roots = freudenstein(phi)
    psi = sw.angular("rocker")[0]
    errs = [np.max(np.abs(wrap(psi - r))) for r in roots]
    branch = int(np.argmin(errs))
    assert errs[branch] < 1e-12  # one root over the whole turn: the branch is kept
    assert errs[1 - branch] > 0.1  # and it is not the other one anywhere near
    # coupler angle from the loop closure b e^{i th3} = d + c e^{i psi} - a e^{i phi}
    z = D_ + C_ * np.exp(1j * roots[branch]) - A_ * np.exp(1j * phi)
    assert np.max(np.abs(np.abs(z) - B_)) < 1e-12
    assert np.max(np.abs(wrap(sw.angular("coupler")[0] - np.angle(z)))) < 1e-12


def test_open_and_crossed_sketches_give_the_two_different_roots():
    got = []
    for crossed in (False, True):
        sw = sweep(four_bar(crossed=crossed), values=1.0 + np.linspace(0, 2 * np.pi, 37))
        psi = sw.angular("rocker")[0]
        errs = [np.max(np.abs(wrap(psi - r))) for r in freudenstein(sw.values)]
        got.append(int(np.argmin(errs)))
    assert sorted(got) == [0, 1]


def test_rocker_velocity_analog_matches_implicit_derivative_of_freudenstein():
    # d/dphi of f(phi, psi) = K1 cos psi - K2 cos phi + K3 - cos(phi - psi) = 0
    K1, K2 = D_ / A_, D_ / C_
    sw = sweep(four_bar(), values=1.0 + np.linspace(0, 2 * np.pi, 181))
    phi, psi = sw.values, sw.angular("rocker")[0]
    f_phi = K2 * np.sin(phi) + np.sin(phi - psi)
    f_psi = -K1 * np.sin(psi) - np.sin(phi - psi)
    dpsi = -f_phi / f_psi
    k = 3 * sw.model.body_index("rocker") + 2
    assert np.max(np.abs(sw.B[:, k, 0] - dpsi)) <= 1e-10 * np.max(np.abs(dpsi))


def test_four_bar_loop_is_found_with_the_driven_link_as_crank():
    model = four_bar().compile()
    loops = four_bar_loops(model, "phi")
    assert len(loops) == 1
    lp = loops[0]
    assert (lp.crank, lp.coupler, lp.rocker) == ("crank", "coupler", "rocker")
    assert lp.joints == ("A", "B", "C", "D")
    rocker_driven = four_bar(drive="rocker").compile()
    lp = four_bar_loops(rocker_driven, "psi")[0]
    assert (lp.crank, lp.rocker) == ("rocker", "crank")
