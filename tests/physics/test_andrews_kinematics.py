"""Andrews' squeezing mechanism against the Test Set for IVP Solvers.

Reference: F. Mazzia, C. Magherini, Test Set for Initial Value Problem Solvers,
release 2.4 (University of Bari, 2008), problem 'andrews' (andrews.f); the problem
is from E. Hairer, G. Wanner, Solving Ordinary Differential Equations II, 2nd ed.,
Springer 1996, section VII.7.

Oracles:
* the Test Set's consistent initial angles (7 angles, one DOF): mechdyn's position
  solve from beta alone must reproduce the other six;
* the Test Set's mass matrix M(q) of the seven angles (andrews.f): the kinetic
  energy of mechdyn's bodies, moved by arbitrary rates of the seven angles taken
  as independent coordinates of the open tree, must equal 1/2 v^T M(q) v.
"""

import numpy as np
import pytest

from mechdyn.examples import andrews
from mechdyn.kinematics import assemble, solve_position
from mechdyn.model.constraints import point_velocity, residual

DEPENDENT = ("Theta", "gamma", "Phi", "delta", "Omega", "epsilon")


@pytest.fixture(scope="module")
def model():
    return andrews.build().compile()


def test_position_solve_reproduces_the_consistent_initial_angles(model):
    rng = np.random.default_rng(7)
    x_guess = model.x_sketch + rng.normal(scale=0.01, size=model.n_x)  # ~1 cm / ~0.6 deg off
    x = assemble(model, q=[andrews.Q0["beta"]], x_guess=x_guess)
    got = andrews.test_set_angles(model, x)
    for name in DEPENDENT:
        assert got[name] == pytest.approx(andrews.Q0[name], abs=1e-12), name
    assert got["beta"] == andrews.Q0["beta"]


def test_newton_from_the_sketch_keeps_the_consistent_angles(model):
    x = solve_position(model, [andrews.Q0["beta"]], model.x_sketch)
    got = andrews.test_set_angles(model, x)
    assert max(abs(got[n] - andrews.Q0[n]) for n in DEPENDENT) < 1e-12


def test_reference_angles_at_t_003_are_reproduced_from_beta(model):
    # The Test Set's solution at t = 0.03 s satisfies the constraints; solving the
    # position at its beta from a nearby pose must give its other six angles (the
    # published values close the loops to about 1e-15 rad).
    poses = andrews.sketch_poses(andrews.REFERENCE_T003)
    x_ref = np.concatenate([poses[b] for b in model.body_names])
    x = solve_position(model, [andrews.REFERENCE_T003["beta"]], x_ref + 1e-4)
    got = andrews.test_set_angles(model, x)
    for name in DEPENDENT:
        assert got[name] == pytest.approx(andrews.REFERENCE_T003[name], abs=1e-12), name


def test_sketch_of_the_consistent_angles_closes_the_loops(model):
    assert np.max(np.abs(residual(model, model.x_sketch))) < 1e-16


def _tree_state(model, angles, rates):
    """Poses and velocities of the open tree driven by seven independent angle rates."""
    poses = andrews.sketch_poses(angles)
    x = np.concatenate([poses[b] for b in model.body_names])
    r = dict(zip(andrews.ANGLE_NAMES, rates, strict=True))
    omega = {"crank": r["beta"], "rod": r["beta"] + r["Theta"], "triangle": r["gamma"],
             "link4": r["Phi"] + r["delta"], "link5": r["delta"],
             "link6": r["Omega"] + r["epsilon"], "link7": r["epsilon"]}
    xdot = np.zeros(model.n_x)
    for b, w in omega.items():
        xdot[3 * model.body_index(b) + 2] = w
    # the origins of rod, link4 and link6 move with their parents' pins F, G, H
    for child, parent, pin in (("rod", "crank", "F"), ("link4", "link5", "G"),
                               ("link6", "link7", "H")):
        k = model.body_index(child)
        xdot[3 * k:3 * k + 2] = point_velocity(model, x, xdot, parent, pin)
    return x, xdot


def _kinetic_energy(model, x, xdot):
    T = 0.0
    for k, b in enumerate(model.body_names):
        vc = point_velocity(model, x, xdot, b, "com")
        w = xdot[3 * k + 2]
        T += 0.5 * model.mass[k] * float(vc @ vc) + 0.5 * model.inertia[k] * w**2
    return T


@pytest.mark.parametrize("which", ["Q0", "T003", "random0", "random1", "random2"])
def test_kinetic_energy_of_the_bodies_equals_the_test_set_mass_matrix(model, which):
    rng = np.random.default_rng(len(which) + ord(which[-1]))
    if which == "Q0":
        angles = dict(andrews.Q0)
    elif which == "T003":
        angles = dict(andrews.REFERENCE_T003)
    else:  # the tree needs no closure: any angles will do
        angles = dict(zip(andrews.ANGLE_NAMES, rng.uniform(-np.pi, np.pi, 7), strict=True))
    M = andrews.test_set_mass_matrix(angles)
    for _ in range(5):
        v = rng.normal(scale=100.0, size=7)
        x, xdot = _tree_state(model, angles, v)
        T_mechdyn = _kinetic_energy(model, x, xdot)
        T_test_set = 0.5 * v @ M @ v
        assert T_mechdyn == pytest.approx(T_test_set, rel=1e-12)


def test_mass_matrix_is_symmetric_positive_definite():
    M = andrews.test_set_mass_matrix(andrews.Q0)
    assert np.array_equal(M, M.T)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    assert np.array_equal(M, andrews.test_set_mass_matrix([andrews.Q0[n]
                                                          for n in andrews.ANGLE_NAMES]))


def test_model_file_holds_the_test_set_data():
    # the geometry is checked by the tests above (loop closure, kinetic energy); here the
    # masses, inertias, ground points and loads of andrews_squeezer.toml
    p = andrews.PARAMS
    mech = andrews.build()
    bodies = ("crank", "rod", "triangle", "link4", "link5", "link6", "link7")
    assert list(mech.bodies) == list(bodies)
    for k, name in enumerate(bodies, start=1):
        b = mech.bodies[name]
        assert (b.mass, b.inertia) == (p[f"m{k}"], p[f"I{k}"]), name
    assert mech.ground.points == {"O": (0.0, 0.0), "A": (p["xa"], p["ya"]),
                                  "B": (p["xb"], p["yb"]), "C": (p["xc"], p["yc"])}
    spring, drive = mech.loads
    assert (spring.body1, spring.point1, spring.body2, spring.point2) == (
        "triangle", "D", "ground", "C")
    assert mech.bodies["triangle"].points["D"] == (p["sd"], -p["sc"])
    assert (spring.stiffness, spring.free_length) == (p["c0"], p["l0"])
    assert (drive.body, drive.magnitude) == ("crank", p["mom"])
    assert mech.gravity == (0.0, 0.0)
    assert andrews.build(loads=False).loads == []
