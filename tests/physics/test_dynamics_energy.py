"""Energy balance of simulated motions: T + U - W_nc = const.

Oracle: the work-energy theorem.  With conservative forces only, T + U is
constant; with drives, dampers and applied forces, their work W_nc (integrated
with the motion) accounts for the change.
"""

import numpy as np
import pytest
from dynamics_models import four_bar, slider_crank

from mechdyn.mechanism import Drive, Force, RotarySpring, Spring, Table, Torque
from mechdyn.simulate.run import simulate

FOUR_BAR_PERIOD = 0.986  # s, measured for four_bar(phi0=0.3) (about 0.9862 s)


def test_free_four_bar_conserves_energy_over_100_periods():
    tr = simulate(four_bar(phi0=0.3), 100 * FOUR_BAR_PERIOD, rtol=1e-12, atol=1e-14,
                  t_eval=np.linspace(0.0, 100 * FOUR_BAR_PERIOD, 1001), progress=False)
    assert tr.success, tr.message
    # it really swings: the crank reverses about twice per period
    reversals = np.sum(np.diff(np.sign(tr.qdot[::1, 0])) != 0)
    assert reversals > 100
    assert np.all(tr.energy["work_nc"] == 0.0)
    scale = np.max(tr.energy["kinetic"])
    assert tr.energy_drift() < 1e-9 * scale
    assert np.max(tr.energy["residual"]) < 1e-12


def loaded_slider_crank():
    mech = slider_crank()
    mech.add(Spring("spring", "ground", "O", "slider", (0.0, 0.0), stiffness=800.0,
                    free_length=0.2, damping=3.0, preload=5.0))
    mech.add(RotarySpring("torsion", "O", stiffness=2.0, free_angle=0.3, damping=0.01))
    mech.add(Force("push", "slider", (0.0, 0.0), Table((0.0, 0.1, 0.2), (0.0, 40.0, -10.0)),
                   direction=(-1.0, 0.0)))
    mech.add(Torque("brake", "rod", -0.5, reaction_body="crank"))
    mech.add(Drive("motor", "phi", 1.5))
    return mech


@pytest.mark.parametrize("backend", ["numpy", "auto"])
def test_balance_with_dampers_forces_and_drive(backend):
    tr = simulate(loaded_slider_crank(), 0.3, rtol=1e-11, atol=1e-13, backend=backend,
                  qdot0={"phi": 20.0}, progress=False)
    assert tr.success, tr.message
    e = tr.energy
    assert np.ptp(e["work_nc"]) > 0.1  # the non-conservative forces do real work
    assert tr.energy_drift() < 1e-8 * max(np.max(e["kinetic"]), np.ptp(e["potential"]))


def test_wilson_balance_converges_second_order():
    drifts = []
    for n in (100, 200, 400):
        tr = simulate(loaded_slider_crank(), 0.2, integrator="wilson", steps=n,
                      qdot0={"phi": 20.0})
        drifts.append(tr.energy_drift())
    slope = np.polyfit(np.log([1 / 100, 1 / 200, 1 / 400]), np.log(drifts), 1)[0]
    assert slope == pytest.approx(2.0, abs=0.3)
