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
