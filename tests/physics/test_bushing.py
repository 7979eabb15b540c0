"""The linear bushing load (mechanism.load.Bushing) against closed forms and balances:
a mass on a bushing is a pair of damped oscillators; two free bodies joined by one keep
their momentum and angular momentum (the force pair has no moment, also when the
housing turns); the energy balance closes; the compiled and the NumPy evaluators agree."""

import numpy as np
import pytest

import mechdyn
from mechdyn import Bushing, Mechanism
from mechdyn.errors import ModelError
from mechdyn.model.forces import force_model

M, KX, KY, CX, CY = 2.0, 8e3, 2e4, 4.0, 12.0  # kg, N/m, N s/m


def block(cx=CX, cy=CY) -> Mechanism:
    """A block whose centre of mass is held to the ground point (0.3, 0.1) by a bushing,
    free in x, y and angle, without gravity."""
    m = Mechanism("block", gravity=(0.0, 0.0))
    m.add_body("block", mass=M, inertia=0.01, pose=(0.3, 0.1, 0.0))
    for kind in ("x", "y"):
        m.add_coordinate(kind, kind=kind, body="block")
    m.add_coordinate("theta", kind="angle", body="block")
    m.add(Bushing("mount", "ground", (0.3, 0.1), "block", (0.0, 0.0), KX, KY, cx, cy))
    return m


def damped(t, x0, k, c):
    """Free damped oscillation of M from rest at x0."""
    wn = np.sqrt(k / M)
    zeta = c / (2 * np.sqrt(k * M))
    wd = wn * np.sqrt(1 - zeta**2)
    return x0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_mass_on_a_bushing_is_two_damped_oscillators(backend):
    t = np.linspace(0.0, 0.3, 301)
    tr = mechdyn.simulate(block(), 0.3, q0={"x": 0.3 + 2e-3, "y": 0.1 - 1e-3, "theta": 0.4},
                          qdot0={"x": 0.0, "y": 0.0, "theta": 0.0}, t_eval=t, rtol=1e-11,
                          atol=1e-13, backend=backend, progress=False)
    assert tr.success
    np.testing.assert_allclose(tr.coordinate("x") - 0.3, damped(t, 2e-3, KX, CX), rtol=0,
                               atol=2e-12)
    np.testing.assert_allclose(tr.coordinate("y") - 0.1, damped(t, -1e-3, KY, CY), rtol=0,
                               atol=2e-12)
    # through its centre of mass, the force puts no moment on the block
    np.testing.assert_allclose(tr.coordinate("theta"), 0.4, rtol=0, atol=1e-12)


def pair(damping: float) -> Mechanism:
    """Two free bodies, the second held at its origin in a bushing of the first at
    (0.5, 0): anisotropic, so the first body's turning matters."""
    m = Mechanism("pair", gravity=(0.0, 0.0))
    m.add_body("a", mass=2.0, inertia=0.1, com=(0.1, 0.0), pose=(0.0, 0.0, 0.0))
    m.add_body("b", mass=3.0, inertia=0.2, com=(0.0, 0.05), pose=(0.5, 0.0, 0.0))
    for b in "ab":
        for kind in ("x", "y"):
            m.add_coordinate(f"{b}_{kind}", kind=kind, body=b)
        m.add_coordinate(f"{b}_theta", kind="angle", body=b)
    m.add(Bushing("bush", "a", (0.5, 0.0), "b", (0.0, 0.0), 2.0, 6.0, damping,
                  2.5 * damping))
    return m


def momenta(model, x, xd):
    """Linear momentum (2,) and angular momentum about the origin of all bodies."""
    P, L = np.zeros(2), 0.0
    for i in range(model.n_bodies):
        th, w = x[3 * i + 2], xd[3 * i + 2]
        c, s = np.cos(th), np.sin(th)
        cx, cy = model.com[i]
        arm = np.array([c * cx - s * cy, s * cx + c * cy])
        rc = x[3 * i:3 * i + 2] + arm
        vc = xd[3 * i:3 * i + 2] + w * np.array([-arm[1], arm[0]])
        P += model.mass[i] * vc
        L += model.mass[i] * (rc[0] * vc[1] - rc[1] * vc[0]) + model.inertia[i] * w
    return P, L


@pytest.mark.parametrize("damping", [0.0, 0.05])
def test_two_bodies_on_a_bushing_keep_their_momenta(damping):
    q0 = {"a_x": 0.0, "a_y": 0.0, "a_theta": 0.0, "b_x": 0.5, "b_y": 0.0, "b_theta": 0.0}
    qd0 = {"a_x": 0.1, "a_y": 0.3, "a_theta": 2.0, "b_x": -0.2, "b_y": 0.1, "b_theta": -1.0}
    runs = {b: mechdyn.simulate(pair(damping), 0.5, q0=q0, qdot0=qd0, rtol=1e-11, atol=1e-13,
                                backend=b, progress=False) for b in ("numba", "numpy")}
    for tr in runs.values():
        assert tr.success
        P0, L0 = momenta(tr.model, tr.x[0], tr.xdot[0])
        for k in range(tr.t.size):
            P, L = momenta(tr.model, tr.x[k], tr.xdot[k])
            assert np.max(np.abs(P - P0)) < 1e-12 and abs(L - L0) < 1e-12
        # the body a turns by tenths of a radian: its bushing axes turn with it
        assert np.max(np.abs(tr.coordinate("a_theta"))) > 0.3
        # kinetic + stored energy + the dampers' work: constant
        assert tr.energy_drift() < 1e-9
    a, b = runs["numba"], runs["numpy"]
    assert np.max(np.abs(a.q[-1] - b.q[-1])) < 1e-12


def test_stored_energy_is_the_potential_of_the_force():
    """The force is minus the gradient of the stored energy, at a turned pose of both
    bodies (central differences)."""
    model = pair(0.0).compile()
    fm = force_model(model)
    x = np.array([0.01, -0.02, 0.7, 0.503, 0.004, -0.3])
    F = fm.conservative(x)
    grad = np.empty(6)
    for i in range(6):
        h = np.zeros(6)
        h[i] = 1e-6
        grad[i] = (fm.potential_energy(x + h) - fm.potential_energy(x - h)) / 2e-6
    np.testing.assert_allclose(F, -grad, rtol=0, atol=1e-6 * np.abs(F).max())


def test_bad_bushings_are_named():
    m = block()
    m.loads[0] = Bushing("mount", "ground", (0.0, 0.0), "blok", (0.0, 0.0), -1.0, 1.0)
    with pytest.raises(ModelError) as err:
        m.compile()
    msg = str(err.value)
    assert "bushing 'mount': kx must be a finite number >= 0, got -1.0" in msg
    assert "bushing 'mount': unknown body 'blok'" in msg and "'block'" in msg
    m.loads[0] = Bushing("mount", "block", (0.0, 0.0), "block", (0.1, 0.0), 1.0, 1.0)
    with pytest.raises(ModelError, match="bushing 'mount': body1 and body2 are the same"):
        m.compile()
