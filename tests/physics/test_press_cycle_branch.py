"""The press cycle keeps its assembly branch at every tolerance.

The chain O-A-B-C of the press closes on the ram's pin C, which slides along x: with the
crank angle phi and the rocker angle psi given, x_C is a root of the loop closure
|B - A| = l2, B = C + l3 (cos psi, sin psi), A = l1 (cos phi, sin phi):

    x_C = A_x - l3 cos psi +/- sqrt(l2^2 - (l3 sin psi - A_y)^2)

and the press runs on the + root (the ram above the rocker's pivot line).  At rtol 1e-8
a trial step about ten times too long once took the position solve of its stages to the
- root, 70 mm below, and the retries of the step went on from there: the ram jumped
there and the run stopped at a dead position of that branch (0.49 s, "singular-position").
Oracle: the closed form above, at every sample, and the event sequence of the run at
rtol 1e-11 (the times to the tolerance of each run).
"""

import numpy as np
import pytest

import mechdyn

L1, L2, L3 = 0.015, 0.040, 0.030  # press_cycle.toml: crank, rod, rocker (m)
X_STOP_UP = 0.028


@pytest.fixture(scope="module")
def press():
    return mechdyn.examples.load("press_cycle").compile()


def _branch_error(tr) -> float:
    """Largest |x_C - (+ root of the loop closure)| over the samples, m."""
    ib = tr.body_names.index("slider")
    phi, psi = tr.q[:, 0], tr.q[:, 1]
    ax, ay = L1 * np.cos(phi), L1 * np.sin(phi)
    root = ax - L3 * np.cos(psi) + np.sqrt(L2**2 - (L3 * np.sin(psi) - ay) ** 2)
    return float(np.max(np.abs(tr.x[:, 3 * ib] - root)))


@pytest.fixture(scope="module")
def reference(press):
    tr = mechdyn.simulate(press, 1.0, progress=False, rtol=1e-11)
    assert tr.success, tr.message
    return tr


@pytest.mark.parametrize("integrator, rtol", [("dop853", 1e-8), ("scipy-dop853", 1e-7)])
def test_press_stays_on_its_branch(press, reference, integrator, rtol):
    tr = mechdyn.simulate(press, 1.0, progress=False, rtol=rtol, integrator=integrator)
    assert tr.status == "success", tr.message
    assert _branch_error(tr) < 1e-9
    ib = tr.body_names.index("slider")
    assert np.max(tr.x[:, 3 * ib]) < X_STOP_UP + 1e-9  # never through its upper stop
    assert [(e.kind, e.element) for e in tr.events] == \
        [(e.kind, e.element) for e in reference.events]
    np.testing.assert_allclose([e.t for e in tr.events], [e.t for e in reference.events],
                               rtol=0, atol=1e-5)


def test_reference_is_on_the_branch(reference):
    assert _branch_error(reference) < 1e-9
    # the ram is held on its upper stop through 0.49 s (the second idle phase)
    ib = reference.body_names.index("slider")
    k = np.searchsorted(reference.t, 0.49)
    assert reference.x[k, 3 * ib] == pytest.approx(X_STOP_UP, abs=1e-9)
