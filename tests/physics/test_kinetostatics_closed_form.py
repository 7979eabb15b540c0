"""Kinetostatics against closed forms: the slider-crank with a gas force, and a
four-bar held against gravity (virtual work on an independent closed form).

Sign conventions checked here (docs/notation.md, "Reactions and driving torques"):
the reaction of a joint is the force ON THE CHILD FROM THE PARENT; the driving
torque is the torque the drive must APPLY to the crank (positive CCW).
"""

import numpy as np
import pytest

import mechdyn as md
from mechdyn.kinetostatics.inverse import kinetostatics
from mechdyn.mechanism import Force

R_CRANK, L_ROD = 0.05, 0.20
OMEGA = 100.0  # rad/s
F_GAS = 1000.0  # N, pushes the piston towards the crank (-x)


def slider_crank(m_piston: float, gravity=(0.0, 0.0)) -> md.Mechanism:
    """Crank O-A (x along the crank), rod A-B (x along the rod), piston B on the x axis."""
    th0 = 0.3
    beta0 = np.arcsin(R_CRANK * np.sin(th0) / L_ROD)
    xb0 = R_CRANK * np.cos(th0) + L_ROD * np.cos(beta0)
    m = md.Mechanism("slider-crank", gravity=gravity)
    m.add_body("crank", points={"A": (R_CRANK, 0.0)}, pose=(0.0, 0.0, th0))
    m.add_body("rod", points={"B": (L_ROD, 0.0)},
               pose=(R_CRANK * np.cos(th0), R_CRANK * np.sin(th0), -beta0))
    m.add_body("piston", mass=m_piston, pose=(xb0, 0.0, 0.0))
    m.add_revolute("O", "ground", "crank")
    m.add_revolute("A", "crank", "rod", "A", (0.0, 0.0))
    m.add_revolute("B", "rod", "piston", "B", (0.0, 0.0))
    m.add_prismatic("P", "ground", "piston", (0.0, 0.0), (1.0, 0.0), (0.0, 0.0))
    m.add_coordinate("phi", "angle", body="crank")
    m.add(Force("gas", "piston", (0.0, 0.0), F_GAS, (-1.0, 0.0)))
    return m


def piston_acceleration(th):
    """Closed-form d^2 x_B / dt^2 at constant crank speed OMEGA."""
    s, sp, spp = R_CRANK * np.sin(th), R_CRANK * np.cos(th), -R_CRANK * np.sin(th)
    c = np.sqrt(L_ROD**2 - s**2)
    cp = -s * sp / c
    xpp = -R_CRANK * np.cos(th) - ((sp**2 + s * spp) * c - s * sp * cp) / c**2
    return OMEGA**2 * xpp


@pytest.mark.parametrize("m_piston", [0.0, 2.5])
def test_slider_crank_matches_closed_form_over_a_cycle(m_piston):
    res = kinetostatics(slider_crank(m_piston), over="phi", speed=OMEGA,
                        values=np.linspace(0.0, 2 * np.pi, 721))
    th = res.values
    beta = np.arcsin(R_CRANK * np.sin(th) / L_ROD)
    # force the rod has to balance on the piston: gas force plus the piston's inertia
    fp = F_GAS + m_piston * piston_acceleration(th)
    f_q = fp / np.cos(beta)  # rod thrust (compression > 0)
    f_n = fp * np.tan(beta)  # side thrust of the wall on the piston (+y)
    t_gas = f_q * R_CRANK * np.sin(th + beta)  # torque the rod puts on the crank (CCW)

    def rel(a, b):
        return np.max(np.abs(a - b)) / np.max(np.abs(b))

    # the drive must apply the opposite of what the rod puts on the crank
    assert rel(res.driving["phi"], -t_gas) < 1e-9
    e = np.stack([np.cos(beta), -np.sin(beta)], axis=-1)  # rod direction A -> B
    assert rel(np.sum(res.reactions["B"] * e, axis=-1), f_q) < 1e-9  # rod pushes the piston
    assert rel(np.sum(res.reactions["A"] * e, axis=-1), f_q) < 1e-9  # crank pushes the rod
    # the wall's force on the piston: normal (+90 deg from the axis) component
    assert rel(res.joint_frame["P"][:, 1], f_n) < 1e-9
    assert rel(res.reactions["P"][:, 1], f_n) < 1e-9
    assert np.max(np.abs(res.joint_frame["P"][:, 0])) < 1e-9 * F_GAS  # no friction
    # massless crank: the rod pushes it with -f_q e at A, so the bearing O must push
    # it with +f_q e (reaction on the crank from the frame)
    assert rel(res.reactions["O"], f_q[:, None] * e) < 1e-9
    # driving power = torque x speed
    np.testing.assert_allclose(res.power["phi"], res.driving["phi"] * OMEGA, rtol=1e-12)


def test_slider_crank_shaking_force_is_gas_force_minus_piston_inertia():
    m_p = 2.5
    res = kinetostatics(slider_crank(m_p), over="phi", speed=OMEGA,
                        values=np.linspace(0.0, 2 * np.pi, 361))
    a = piston_acceleration(res.values)
    # the gas force's reaction goes to the cylinder head (not to the frame here)
    np.testing.assert_allclose(res.frame_force[:, 0], -F_GAS - m_p * a, rtol=0,
                               atol=1e-9 * F_GAS)
    np.testing.assert_allclose(res.frame_force[:, 1], 0.0, atol=1e-9 * F_GAS)
    # with the cylinder head part of the frame, the gas force cancels out
    res2 = kinetostatics(slider_crank(m_p), over="phi", speed=OMEGA,
                         values=np.linspace(0.0, 2 * np.pi, 361), reacting_loads=["gas"])
    np.testing.assert_allclose(res2.frame_force[:, 0], -m_p * a, atol=1e-9 * F_GAS)


# ---------------------------------------------------------------- static four-bar
D_GROUND, A_CRANK, B_COUPLER, C_ROCKER = 0.30, 0.10, 0.28, 0.20
MASS = {"crank": 1.2, "coupler": 2.3, "rocker": 1.7}
INERTIA = {"crank": 0.002, "coupler": 0.02, "rocker": 0.01}
COM = {"crank": (0.04, 0.01), "coupler": (0.12, 0.03), "rocker": (0.08, -0.02)}
G = np.array([0.0, -9.81])


def fourbar_closed_form(phi):
    """COM positions of the crank, coupler and rocker (open branch, B above the ground line),
    from the law of cosines. Works with complex phi (complex-step differentiation)."""
    A = np.array([A_CRANK * np.cos(phi), A_CRANK * np.sin(phi)])
    O4 = np.array([D_GROUND, 0.0])
    dvec = O4 - A
    d2 = dvec[0] ** 2 + dvec[1] ** 2
    dist = np.sqrt(d2)
    # distance from A to the foot of B on line A-O4, and the height of B over that line
    along = (B_COUPLER**2 - C_ROCKER**2 + d2) / (2 * dist)
    h = np.sqrt(B_COUPLER**2 - along**2)
    e = dvec / dist
    n = np.array([-e[1], e[0]])
    B = A + along * e + h * n
    out = {}
    for name, P, Q, L in (("crank", np.zeros(2), A, A_CRANK), ("coupler", A, B, B_COUPLER),
                          ("rocker", O4, B, C_ROCKER)):
        u = (Q - P) / L
        v = np.array([-u[1], u[0]])
        s = COM[name]
        out[name] = P + s[0] * u + s[1] * v
    return out, B


def fourbar(phi0=1.0) -> md.Mechanism:
    rc, B = fourbar_closed_form(phi0)
    A = np.array([A_CRANK * np.cos(phi0), A_CRANK * np.sin(phi0)])
    th3 = np.arctan2(*(B - A)[::-1])
    th4 = np.arctan2(B[1], B[0] - D_GROUND)
    m = md.Mechanism("four-bar", gravity=tuple(G))
    m.add_ground({"O2": (0.0, 0.0), "O4": (D_GROUND, 0.0)})
    for name, pose, pt in (("crank", (0.0, 0.0, phi0), {"A": (A_CRANK, 0.0)}),
                           ("coupler", (*A, th3), {"B": (B_COUPLER, 0.0)}),
                           ("rocker", (D_GROUND, 0.0, th4), {"B": (C_ROCKER, 0.0)})):
        m.add_body(name, mass=MASS[name], inertia=INERTIA[name], com=COM[name], points=pt,
                   pose=pose)
    m.add_revolute("O2", "ground", "crank", "O2", (0.0, 0.0))
    m.add_revolute("A", "crank", "coupler", "A", (0.0, 0.0))
    m.add_revolute("B", "coupler", "rocker", "B", "B")
    m.add_revolute("O4", "ground", "rocker", "O4", (0.0, 0.0))
    m.add_coordinate("phi", "angle", body="crank")
    return m


def test_fourbar_static_torque_equals_virtual_work_of_gravity():
    phis = np.linspace(0.2, 2 * np.pi - 0.2, 40)
    res = kinetostatics(fourbar(1.0), over="phi", speed=0.0, values=phis)
    assert res.status == "success"
    h = 1e-30
    expected = []
    for p in phis:
        rc, _ = fourbar_closed_form(p + 1j * h)
        # T = - sum m g . d r_c / d phi (complex step: exact to round-off)
        expected.append(-sum(MASS[k] * (G @ (rc[k].imag / h)) for k in rc))
    expected = np.array(expected)
    np.testing.assert_allclose(res.driving["phi"], expected, rtol=0,
                               atol=1e-10 * np.max(np.abs(expected)))
    # at rest: no power, and the frame carries exactly the weight
    assert np.all(res.power["phi"] == 0.0)
    weight = sum(MASS.values()) * G
    np.testing.assert_allclose(res.frame_force, np.broadcast_to(weight, (phis.size, 2)),
                               atol=1e-9 * np.linalg.norm(weight))


def test_fourbar_positions_follow_the_closed_form_branch():
    phis = np.linspace(0.0, 2 * np.pi, 91)
    res = kinetostatics(fourbar(1.0), over="phi", speed=3.0, values=phis)
    for k, p in enumerate(phis):
        rc, B = fourbar_closed_form(p)
        xr = res.x[k, 6:9]
        tip = xr[:2] + C_ROCKER * np.array([np.cos(xr[2]), np.sin(xr[2])])
        np.testing.assert_allclose(tip, B, atol=1e-12)
