"""The bundled press on the elastic mounts of its [foundation] table, coupled
(mechdyn.foundation.mounted): it does the same work strokes as on its fixed frame."""

import warnings

import pytest

import mechdyn
from mechdyn.foundation import mounted

T_END = 1.0  # two commands: idle, engage, lock, work stroke, release, twice
BED = ("ram_springs", "cylinder_force", "punch")  # forces the frame reacts


def strokes(run) -> tuple[int, int]:
    """(locks engaged, locks released): the work strokes of a press run."""
    kinds = [(e.kind, e.element) for e in run.events]
    assert ("ignored", "lock_on") not in kinds  # the rocker never passes psi = 0 unlocked
    return (kinds.count(("engage", "rocker_lock")), kinds.count(("release", "rocker_lock")))


@pytest.fixture(scope="module")
def rigid():
    return mechdyn.simulate(mechdyn.examples.load("press_cycle"), T_END, progress=False)


def test_press_tables_measure_the_ram_on_its_frame():
    # springs and punch over the ram's travel on its guide: nothing measures against the
    # floor once the frame is mounted
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mm = mounted(mechdyn.examples.load("press_cycle"))
    assert {ld.magnitude.variable for ld in mm.loads if ld.name in ("ram_springs", "punch")} \
        == {"joint:guide"}


@pytest.mark.slow
@pytest.mark.parametrize("bed", [(), BED], ids=["external", "bed"])
def test_mounted_press_does_the_work_strokes_of_the_rigid_one(rigid, bed):
    assert rigid.status == "success", rigid.message
    assert strokes(rigid) == (2, 2)
    run = mechdyn.simulate(mounted(mechdyn.examples.load("press_cycle"), reacting=bed),
                           T_END, progress=False)
    assert run.status == "success", run.message
    assert strokes(run) == strokes(rigid)
    # each lock at the rocker's arrival on the ram axis with the ram below the change
    # point (25 mm on the base), in the same revolution as on the fixed frame
    k = run.coordinate_names.index("phi")
    for a, b in zip([e for e in rigid.events if e.element == "rocker_lock"],
                    [e for e in run.events if e.element == "rocker_lock"], strict=True):
        assert a.kind == b.kind
        assert abs(a.q_before[k] - b.q_before[k]) < 0.5  # rad, well within a revolution


@pytest.mark.slow
def test_mounted_press_at_a_tight_tolerance_runs_to_the_end():
    """At rtol 1e-12 the compiled loop crosses the cylinder command's point (183 deg) just
    after a rejected step: it used to go on with the short step that reached the point,
    land short of it again and again and stop on the smallest step (t = 0.9427 s).
    Oracle: SciPy's DOP853 on the same model and tolerance, stepped from Python."""
    import numpy as np

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mechdyn.foundation.FloorFrameWarning)
        model = mounted(mechdyn.examples.load("press_cycle"), reacting=BED)
    grid = np.linspace(0.0, T_END, 1001)
    a = mechdyn.simulate(model, T_END, progress=False, rtol=1e-12, t_eval=grid)
    b = mechdyn.simulate(model, T_END, progress=False, rtol=1e-12, t_eval=grid,
                         integrator="scipy-dop853")
    assert a.status == "success", a.message
    assert b.status == "success", b.message
    # measured: 2.2e-11 rad (phi), 5.2e-10 rad (psi), 5.3e-13 m (p), 1.7e-11 s (events)
    dq = np.max(np.abs(a.q[np.isin(a.t, grid)] - b.q[np.isin(b.t, grid)]), axis=0)
    assert np.all(dq < 1e-8), dq
    # events of the same elements (those of one instant in either order; the kind of a
    # grazing one, the piston at rest on its stop as its reaction vanishes, an impact or
    # a separation by round-off) at the same times
    assert sorted(e.element for e in a.events) == sorted(e.element for e in b.events)
    ta, tb = np.sort([e.t for e in a.events]), np.sort([e.t for e in b.events])
    assert np.max(np.abs(ta - tb)) < 1e-9
