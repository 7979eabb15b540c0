"""The HTML report (issue 14 item 14, issue 11 item 4): rounded tables with units, merged
events, kinetostatics of a 2-DOF machine with the held coordinate stated, interactive
figures with the events and modes marked, and the loads on the building with the peak
load of every support of a foundation."""

import re

import numpy as np
import pytest

import mechdyn
from mechdyn.cli.report import foundation_loads, mounted_loads, report, report_records
from mechdyn.foundation import AnchorBolt, Foundation, Isolator, support_loads
from mechdyn.kinematics.sweep import initial_coordinates
from mechdyn.results.report import report_trajectory, write_report
from mechdyn.results.report_events import merged_events, mode_spans
from mechdyn.results.report_figures import MAX_POINTS, decimate, trajectory_figure
from mechdyn.results.report_html import fmt, heading, table


def _rows(text: str, title: str) -> list[list[str]]:
    """The cells of the table under ``<h3>title</h3>``, row by row (header first)."""
    part = text.split(f"<h3>{title}</h3>", 1)[1].split("</table>", 1)[0]
    return [re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", r) for r in part.split("<tr>")[1:]]


@pytest.fixture(scope="module")
def press_run():
    """The press cycle for 0.5 s: locks, stops and impacts, several elements per event."""
    return mechdyn.simulate(mechdyn.examples.load("press_cycle"), 0.5,
                            t_eval=np.linspace(0.0, 0.5, 1001), progress=False)


def test_numbers_are_rounded_and_headings_carry_units():
    assert fmt(1234.5678) == "1235" and fmt(0.000123456) == "1.235e-04"
    assert fmt(-12.3456, 6) == "-12.3456" and fmt(100.0) == "100"
    assert heading("J_c_kg_m2") == "J_C (kg m²)" and heading("omega_rad_s") == "omega (rad/s)"
    html = table("T", [{"com_x_mm": 12.345678, "body": "rod"}])
    assert "<th>com x (mm)</th>" in html and "<td>12.35</td>" in html


def test_decimation_keeps_the_peaks_and_the_size():
    t = np.linspace(0.0, 1.0, 50_001)
    y = np.sin(40 * t) + (t == t[31_234]) * 5.0  # one spike
    xs, ys = decimate(t, y)
    assert len(xs) <= MAX_POINTS + 2 and ys.max() == y.max() and ys.min() == y.min()
    assert np.all(np.diff(xs) > 0)


def test_events_of_one_transition_are_one_row(press_run):
    raw = press_run.events
    merged = merged_events(raw)
    assert len(merged) < len(raw)
    keys = [(round(e.t, 12), e.mode_before, e.mode_after) for e in merged]
    assert len(set(keys)) == len(keys)  # no duplicates left
    # every record is in exactly one merged event
    assert sum(len(e.elements) for e in merged) == len(raw)
    for e in merged:
        lost = {r.energy_lost for r in raw if r.t == e.t and r.element in e.elements}
        assert e.energy_lost == max(lost)  # counted once, not once per element


def test_simulation_figure_marks_events_and_shades_modes(press_run):
    vs = press_run.switching
    spans = mode_spans(press_run.t, vs["mode_index"], vs["modes"])
    merged = merged_events(press_run.events)
    fig = trajectory_figure(press_run, transitions=merged, spans=spans)
    events = [tr for tr in fig.data if tr.legendgroup == "events"]
    assert events and all(sum(x is not None for x in tr.x) == 2 * len(merged) for tr in events)
    assert len(fig.layout.shapes) == len(spans) and len(spans) > 3
    assert {s.name for s in fig.layout.shapes if s.showlegend} == \
        {f"mode {label}" for _, _, label in spans}
    assert all(len(tr.x) <= MAX_POINTS + 2 for tr in fig.data)


def test_simulation_report_lists_each_event_once(press_run, tmp_path):
    text = report_trajectory(press_run, tmp_path / "run.html", animation=False).read_text(
        encoding="utf-8")
    rows = _rows(text, "Events")
    assert len(rows) - 1 == len(merged_events(press_run.events))
    head = rows[0]
    assert "phi after (deg)" in head and "p after (mm)" in head
    impact = next(r for r in rows[1:] if r[1] == "impact" and "+" in r[2])
    assert float(impact[head.index("energy lost (J)")]) > 0
    assert "<h2>Loads on the building</h2>" in text and "switching events" in text


def test_two_dof_press_gets_kinetostatics_with_the_other_coordinate_held(tmp_path):
    mech = mechdyn.examples.load("clutchless_press")
    assert mech.dof == 2
    model, sw, ks = report_records(mech, steps=73)
    psi0 = float(initial_coordinates(model)[1])
    assert ks.driven == ("phi", "psi") and np.allclose(ks.q[:, 1], psi0)
    text = write_report(model, tmp_path / "r.html", sweep=sw, kinetostatics=ks,
                        animation=False).read_text(encoding="utf-8")
    assert "<h2>Kinetostatics</h2>" in text
    stated = re.search(r"<code>psi</code> at (-?[0-9.]+) deg \(its initial value\)", text)
    assert stated and float(stated.group(1)) == pytest.approx(np.rad2deg(psi0), abs=0.006)
    drives = _rows(text, "Driving torque")
    assert [r[:2] for r in drives[1:]] == [["phi", "driven"], ["psi", "held"]]


def _two_bolts() -> Foundation:
    return Foundation([AnchorBolt("left", -0.4, 0.0, 2e8, 1e8, preload=2e3),
                       AnchorBolt("right", 0.4, 0.0, 2e8, 1e8, preload=2e3)])


def test_building_section_has_the_peak_of_every_support(tmp_path):
    mech = mechdyn.examples.load("slider_crank")
    mech.foundation = _two_bolts()  # as a model file's [foundation] would set it
    text = report(mech, tmp_path / "r.html", speed=157.0, steps=73,
                  animation=False).read_text(encoding="utf-8")
    assert "<h2>Loads on the building</h2>" in text and "<h3>Supports</h3>" in text
    rows = _rows(text, "Supports")
    head, by_name = rows[0], {r[0]: r for r in rows[1:]}
    assert set(by_name) == {"left", "right"}
    _, _, ks = report_records(mech, speed=157.0, steps=73)
    expected = support_loads(mech.foundation, ks).peaks()
    for name, r in by_name.items():
        assert float(r[head.index("peak |F| (kN)")]) == pytest.approx(
            expected[name]["resultant_max_N"] / 1e3, rel=1e-3)
        assert float(r[head.index("peak tension (kN)")]) == pytest.approx(
            expected[name]["tension_max_N"] / 1e3, rel=1e-3)
    assert "keeps its preload" in text or "opens first" in text


def test_run_report_with_isolators_lists_them(press_run, tmp_path):
    fnd = Foundation([Isolator("a", -0.5, -0.3, 2e5, 5e5, cy=2e3),
                      Isolator("b", 0.5, -0.3, 2e5, 5e5, cy=2e3)])
    loads = support_loads(fnd, press_run)
    text = report_trajectory(press_run, tmp_path / "run.html", animation=False,
                             supports=loads).read_text(encoding="utf-8")
    rows = _rows(text, "Supports")
    assert [r[:2] for r in rows[1:]] == [["a", "isolator"], ["b", "isolator"]]
    assert "bolt" not in "".join(rows[0])


def test_run_report_on_elastic_mounts_compares_the_floor_force(press_run, tmp_path):
    """press_cycle's [foundation]: levelling mounts with the base's mass and inertia."""
    mech = mechdyn.examples.load("press_cycle")
    assert mech.foundation is not None and mech.foundation.mass is not None
    loads = foundation_loads(mech, press_run)
    mounted, modes = mounted_loads(mech, loads)
    text = report_trajectory(press_run, tmp_path / "run.html", animation=False,
                             supports=loads, mounted=mounted, modes=modes).read_text(
        encoding="utf-8")
    rows = _rows(text, "Force passed to the floor")
    head, rigid, elastic = rows[0], rows[1], rows[2]
    k = head.index("peak |F| (kN)")
    frame = np.hypot(loads.applied[:, 0], loads.applied[:, 1]).max() / 1e3
    floor = np.hypot(mounted.floor[:, 0], mounted.floor[:, 1]).max() / 1e3
    assert float(rigid[k]) == pytest.approx(frame, rel=1e-3)
    assert float(elastic[k]) == pytest.approx(floor, rel=1e-3)
    freqs = _rows(text, "Natural frequencies of the mounted base")
    assert [float(r[1]) for r in freqs[1:]] == pytest.approx(modes.frequencies, rel=1e-3)
