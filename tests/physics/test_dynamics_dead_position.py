"""A four-bar driven from its rocker by a torque swings into the rocker's dead position
(crank and coupler in line): the run stops with status "singular-position", says when
and where, and keeps the motion computed so far."""

import re

import numpy as np
import pytest
from dynamics_models import four_bar

from mechdyn.mechanism import Drive
from mechdyn.simulate.run import simulate


def rocker_driven():
    mech = four_bar("psi", gravity=(0.0, 0.0))
    mech.add(Drive("push", "psi", 2.0))
    return mech


@pytest.mark.parametrize("integrator, opts", [("dop853", {}), ("rk4", {"steps": 1000}),
                                              ("wilson", {"steps": 1000}),
                                              ("scipy-dop853", {}), ("rk45", {}), ("bdf", {}),
                                              ("lsoda", {})])
def test_runs_into_dead_position(integrator, opts):
    tr = simulate(rocker_driven(), 1.0, integrator=integrator, progress=False, **opts)
    assert tr.status == "singular-position"
    assert not tr.success
    assert re.search(r"t = 0\.3[01]\d* s", tr.message), tr.message
    assert "psi" in tr.message
    # the data up to the stop is kept
    assert tr.t.size > 10
    assert 0.29 < tr.t[-1] < 0.32
    assert np.all(np.isfinite(tr.q)) and np.all(np.isfinite(tr.x))
    # the rocker turned towards its extreme and nearly stopped there
    assert tr.q[-1, 0] > tr.q[0, 0]
    assert abs(tr.qdot[-1, 0]) < 0.2 * np.max(np.abs(tr.qdot[:, 0]))


def test_dead_position_data_in_dataframe():
    tr = simulate(rocker_driven(), 1.0, integrator="rk4", steps=1000)
    df = tr.to_dataframe()
    assert len(df) == tr.t.size
    assert {"t_s", "psi_rad", "psi_deg", "psi_dot_rad_s", "psi_ddot_rad_s2", "T_J", "U_J",
            "W_nc_J", "E_balance_J"} <= set(df.columns)


def test_a_switched_run_reports_the_dead_position_too():
    """The same rocker-driven four-bar with a stop it never reaches runs on the segment
    loop of variable-structure models: it stops at the same dead position, says when
    and where, and keeps the motion so far."""
    from mechdyn.mechanism.contact import Stop
    from mechdyn.mechanism.switch import add_element

    mech = rocker_driven()
    add_element(mech, Stop("far", "psi", upper=10.0))
    tr = simulate(mech, 1.0, progress=False)
    assert tr.status == "singular-position", tr.message
    assert re.search(r"t = 0\.3[01]\d* s", tr.message), tr.message
    assert "psi" in tr.message
    assert 0.29 < tr.t[-1] < 0.32 and tr.t.size > 10
    assert np.all(np.isfinite(tr.q)) and np.all(np.isfinite(tr.x))
