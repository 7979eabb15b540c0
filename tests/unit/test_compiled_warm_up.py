"""The compiled kernels are warmed up on their own small model, never on the user's at a
position its run does not visit: a pendulum whose spring ends meet at the sketch
(q = 0) but never during the run simulates on the compiled path as on NumPy."""

import numpy as np

from mechdyn.mechanism import Mechanism, Spring
from mechdyn.simulate.run import simulate


def _pendulum_with_spring():
    m = Mechanism("pendulum with a spring whose ends meet at the sketch", gravity=(0, -9.81))
    m.add_ground(points={"A": (1.0, 0.0)})
    m.add_body("bar", mass=1.0, inertia=0.1, com=(0.5, 0.0), points={"E": (1.0, 0.0)},
               pose=(0.0, 0.0, 0.0))
    m.add_revolute("O", "ground", "bar")
    m.add_coordinate("theta", kind="angle", body="bar")
    m.add(Spring("k", "ground", "A", "bar", "E", stiffness=10.0, free_length=0.1))
    return m


def test_a_spring_meeting_only_at_the_sketch_runs_compiled_as_on_numpy():
    te = np.linspace(0.0, 0.5, 11)
    fast = simulate(_pendulum_with_spring(), 0.5, q0=[0.5], t_eval=te, progress=False)
    ref = simulate(_pendulum_with_spring(), 0.5, q0=[0.5], t_eval=te, progress=False,
                   backend="numpy")
    assert fast.status == ref.status == "success"
    assert fast.stats["backend"] == "numba"
    np.testing.assert_allclose(fast.q, ref.q, rtol=1e-8, atol=1e-10)


def test_warmup_compiles_the_types_the_study_and_the_loop_pass():
    """After mechdyn.warmup(), a batched study and a run in the compiled loop compile
    nothing more (no new specialization of their kernels)."""
    import pytest

    from mechdyn.compiler import warmup
    from mechdyn.kernels.rows_numba import NUMBA

    if not NUMBA:
        pytest.skip("numba not installed")
    from mechdyn.kernels import dop853_numba, fixed_step_numba, rows_variants
    from mechdyn.study.analyses import KinetostaticExtremes
    from mechdyn.study.batch import kinetostatic_batch
    from mechdyn.study.parameters import BaseModel

    times = warmup()
    assert {"dynamics", "integration loop", "kinematic sweep", "batched study"} <= set(times)
    kernels = (rows_variants.path_variants, rows_variants.inverse_variants, dop853_numba.run,
               fixed_step_numba.run)
    before = [len(k.signatures) for k in kernels]
    base = BaseModel("slider_crank")
    p = base.parameter("bodies.rod.mass")
    out = kinetostatic_batch([base.compile({p: m}) for m in (1.0, 2.0)],
                             KinetostaticExtremes("1000 rpm", steps=12))
    assert all(o is not None for o in out)
    tr = simulate(_pendulum_with_spring(), 0.1, q0=[0.5], progress=False)
    assert tr.stats["backend"] == "numba"
    for integ in ("rk4", "wilson"):
        simulate(_pendulum_with_spring(), 0.1, q0=[0.5], integrator=integ, progress=False)
    assert [len(k.signatures) for k in kernels] == before
