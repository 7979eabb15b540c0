"""The end state of a slider-crank run through its motor's knee converges with rtol on
every adaptive integrator.

The bundled slider-crank's motor is a torque-speed table, 30 N m at standstill falling to
0 at 3000 rpm and held at 0 above: a knee at 3000 rpm where dT/domega jumps from
-30 N m / (3000 rpm) to 0.  Started at 2950 rpm the crank's speed swings between about
2735 and 3285 rpm in every turn and crosses the knee 100 times in 0.5 s.  An integrator
whose steps straddle the knee loses its order there: the compiled DOP853 loop (the
default) holds the table's piece through a step and ends its steps at the knee
(:mod:`mechdyn.kernels.table_regions`), SciPy's methods evaluate the table as it is.

Oracle: the crank angle and speed at 0.5 s of the default integrator at rtol 1e-13,
checked here against SciPy's DOP853 at rtol 1e-13 (a different implementation with a
different step sequence that does not stop at the knee; they agree to 6.9e-11 rad)
and measured against Radau at rtol 1e-12 (an implicit collocation method: 4.8e-11 rad).

Measured errors of the crank angle phi at 0.5 s (rad; phi(0.5 s) = 158.73 rad), atol =
1e-3 rtol (the speed's errors, rad/s of 307.8 rad/s, are 25 to 30 times these):

============  =======  =======  =======  =======  =======
rtol          1e-8     1e-9     1e-10    1e-11    1e-12
============  =======  =======  =======  =======  =======
dop853        2.1e-6   5.5e-6   9.0e-9   4.6e-10  1.0e-11
scipy-dop853  7.8e-6   1.3e-6   7.4e-7   6.2e-8   6.9e-9
rk45          6.0e-5   4.4e-6   4.8e-7   2.3e-8   1.8e-9
rk23          3.7e-5   4.4e-6   4.9e-7   5.2e-8   (budget: > 200,000 steps)
radau         1.0e-6   2.1e-7   2.1e-7   5.1e-10  4.8e-11
bdf           1.1e-4   6.5e-6   1.3e-6   2.1e-7   3.7e-8
lsoda         1.5e-5   1.0e-6   4.5e-7   6.6e-8   1.1e-8
============  =======  =======  =======  =======  =======

Every method's error falls with rtol (by 90x to 4400x from rtol 1e-9 to 1e-12 on SciPy's,
85x from 1e-9 to 1e-11 on rk23), but the SciPy methods, which step across the knee, end
5 to 3700 times further off at rtol 1e-12 than the compiled loop (1.0e-11 rad) and fall
irregularly (scipy-dop853 and radau hardly improve from 1e-9 to 1e-10).  The compiled
loop is itself off at rtol 1e-9 by more than at 1e-8 (5.5e-6 rad), then falls 600x to
rtol 1e-10.
"""

import math

import numpy as np
import pytest

from mechdyn.dynamics.compiled import numba_available
from mechdyn.examples import load
from mechdyn.simulate.run import simulate

needs_numba = pytest.mark.skipif(not numba_available(), reason="numba not installed")

T_END = 0.5
PHI0 = math.radians(30.0)
W0 = 2950.0 * math.pi / 30.0  # rad/s
KNEE = 3000.0 * math.pi / 30.0


@pytest.fixture(scope="module")
def crank():
    return load("slider_crank").compile()


def _end(model, rtol, integrator="dop853", **kw):
    tr = simulate(model, T_END, integrator=integrator, rtol=rtol, atol=1e-3 * rtol,
                  q0=[PHI0], qdot0=[W0], t_eval=[T_END], progress=False, **kw)
    assert tr.success, tr.message
    return np.array([tr.q[-1, 0], tr.qdot[-1, 0]])


@pytest.fixture(scope="module")
def reference(crank):
    return _end(crank, 1e-13)


@needs_numba
@pytest.mark.timeout(120)
def test_the_run_crosses_the_knee_about_a_hundred_times(crank):
    tr = simulate(crank, T_END, rtol=1e-10, q0=[PHI0], qdot0=[W0],
                  t_eval=np.linspace(0.0, T_END, 20001), progress=False)
    w = tr.qdot[:, 0]
    crossings = int(np.sum(np.diff(np.sign(w - KNEE)) != 0))
    assert 80 <= crossings <= 120
    assert w.min() < 0.95 * KNEE and w.max() > 1.05 * KNEE


@needs_numba
@pytest.mark.timeout(120)
def test_the_reference_agrees_with_scipy_dop853_at_its_tightest(crank, reference):
    other = _end(crank, 1e-13, "scipy-dop853")
    assert abs(other[0] - reference[0]) < 2e-10  # rad (measured 6.9e-11)
    assert abs(other[1] - reference[1]) < 5e-9  # rad/s (measured 1.7e-9)


@needs_numba
@pytest.mark.timeout(120)
def test_the_compiled_loop_converges_at_its_order(crank, reference):
    errs = {r: np.abs(_end(crank, r) - reference) for r in (1e-9, 1e-12)}
    assert errs[1e-12][0] < 1e-10 and errs[1e-12][1] < 3e-9  # measured 1.0e-11, 2.6e-10
    assert errs[1e-12][0] * 30 < errs[1e-9][0]


#: method -> (coarse rtol, fine rtol, bound on the angle's error at the fine one, rad:
#: about 5x the measured)
SCIPY_CASES = {
    "scipy-dop853": (1e-9, 1e-12, 4e-8),
    "rk45": (1e-9, 1e-12, 1e-8),
    "lsoda": (1e-9, 1e-12, 6e-8),
    "bdf": (1e-9, 1e-12, 2e-7),
    "radau": (1e-9, 1e-12, 3e-10),
    # rk23 needs more than the default budget of 200,000 steps at rtol 1e-12
    "rk23": (1e-9, 1e-11, 3e-7),
}
SLOW = {"bdf", "radau", "rk23"}  # more than 20 s for the two runs


@needs_numba
@pytest.mark.timeout(300)
@pytest.mark.parametrize("method", [pytest.param(m, marks=pytest.mark.slow) if m in SLOW
                                    else m for m in SCIPY_CASES])
def test_scipy_methods_converge_through_the_knee(crank, reference, method):
    coarse, fine, bound = SCIPY_CASES[method]
    errs = {r: np.abs(_end(crank, r, method) - reference) for r in (coarse, fine)}
    assert errs[fine][0] < bound
    assert errs[fine][0] * 30 < errs[coarse][0]
    assert errs[fine][1] * 30 < errs[coarse][1]
