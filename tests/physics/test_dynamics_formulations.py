"""The exact formulation against the source paper's finite-difference analogs (error
O(d^2), measured slope), and the compiled kernel against the NumPy reference path."""

import numpy as np
import pytest
from dynamics_models import four_bar, slider_crank
from test_dynamics_energy import loaded_slider_crank

from mechdyn.dynamics.lagrange import EquationsOfMotion, potential_energy
from mechdyn.examples.paper_case import press_idle
from mechdyn.simulate.run import initial_state

D_DEG = np.array([0.4, 0.2, 0.1, 0.05])


def slope(hs, errs):
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


@pytest.mark.parametrize("build, qdot", [(lambda: four_bar(), [6.0]),
                                         (lambda: slider_crank("phi"), [15.0]),
                                         (lambda: slider_crank("s"), [0.8]),
                                         (press_idle, [43.5, 0.0])])
def test_analogs_agree_with_exact_to_second_order(build, qdot):
    model = build().compile()
    q, _, x = initial_state(model)
    qdot = np.array(qdot, float)
    exact = EquationsOfMotion(model, x0=x, backend="numpy").terms(0.0, q, qdot)
    errs = {"qddot": [], "A": [], "c": [], "Q": []}
    # travel coordinates take d times the length scale (default_displacement)
    for d in np.deg2rad(D_DEG):
        scale = np.where(model.coord_is_angle, 1.0, model.length_scale)
        fd = EquationsOfMotion(model, "analogs", d=d * scale, x0=x).terms(0.0, q, qdot)
        errs["qddot"].append(np.max(np.abs(fd.qddot - exact.qddot)))
        errs["A"].append(np.max(np.abs(fd.A - exact.A)))
        errs["c"].append(np.max(np.abs(fd.c - exact.c)))
        errs["Q"].append(np.max(np.abs(fd.Q - exact.Q)))
    for key, e in errs.items():
        assert slope(D_DEG, e) == pytest.approx(2.0, abs=0.15), key
    # and at the paper's d = 0.1 deg the difference is small against the terms' sizes
    size = np.max(np.abs(np.concatenate([exact.Q, exact.c])) / np.diag(exact.A).min())
    assert errs["qddot"][2] < 2e-3 * size


def test_analogs_generalized_forces_from_potential():
    """Q of the conservative forces = -dU/dq (central differences of the potential)."""
    model = press_idle(drive_torque=0.0, support_stiffness=None).compile()
    q, _, x = initial_state(model)
    tm = EquationsOfMotion(model, x0=x, backend="numpy").terms(0.0, q, np.zeros(2))
    h = 1e-5
    eom = EquationsOfMotion(model, x0=x, backend="numpy")
    dU = []
    for k in range(2):
        e = np.zeros(2)
        e[k] = h
        dU.append((potential_energy(model, eom.positions(q + e))
                   - potential_energy(model, eom.positions(q - e))) / (2 * h))
    np.testing.assert_allclose(tm.Q, -np.array(dU), rtol=1e-6, atol=1e-5)


@pytest.mark.parametrize("build", [loaded_slider_crank, lambda: slider_crank("s"), press_idle,
                                   four_bar])
def test_compiled_kernel_equals_numpy(build):
    model = build().compile()
    fast = EquationsOfMotion(model)
    if fast.backend != "numba":
        pytest.skip(f"compiled backend not available: {fast.backend_note}")
    slow = EquationsOfMotion(model, backend="numpy")
    q0, _, x0 = initial_state(model)
    rng = np.random.default_rng(1)
    for t in (0.0, 0.05, 0.13):
        q = q0 + 0.02 * rng.standard_normal(model.n_q)
        qdot = 5.0 * rng.standard_normal(model.n_q)
        fast.reset(x0)
        slow.reset(x0)
        a1, p1 = fast.rhs(t, q, qdot)
        a2, p2 = slow.rhs(t, q, qdot)
        np.testing.assert_allclose(a1, a2, rtol=1e-12, atol=1e-12 * (1 + np.abs(a2).max()))
        np.testing.assert_allclose(p1, p2, rtol=1e-12, atol=1e-12 * (1 + abs(p2[0])))
        np.testing.assert_allclose(fast.positions(q), slow.positions(q), atol=1e-14)


def test_python_callable_load_falls_back_to_numpy():
    from mechdyn.mechanism import Torque

    mech = four_bar()
    mech.add(Torque("custom", "crank", lambda ctx: -0.1 * ctx.rate("phi")))
    eom = EquationsOfMotion(mech.compile())
    assert eom.backend == "numpy"
    assert "custom" in eom.backend_note


def test_singular_mass_matrix_is_reported():
    from mechdyn import Mechanism
    from mechdyn.errors import IntegrationError

    mech = Mechanism("massless", gravity=(0.0, 0.0))
    mech.add_body("bar", mass=0.0, inertia=0.0, com=(0.5, 0.0))
    mech.add_revolute("O", "ground", "bar")
    mech.add_coordinate("theta", kind="angle", body="bar")
    for backend in ("numpy", "auto"):
        eom = EquationsOfMotion(mech.compile(), backend=backend)
        with pytest.raises(IntegrationError, match="mass matrix"):
            eom.rhs(0.0, np.array([0.0]), np.array([1.0]))


def test_without_numba_the_numpy_path_is_used(monkeypatch):
    from mechdyn.dynamics import compiled

    monkeypatch.setattr(compiled, "_NUMBA", False)
    eom = EquationsOfMotion(four_bar().compile())
    assert eom.backend == "numpy"
    assert "numba" in eom.backend_note
