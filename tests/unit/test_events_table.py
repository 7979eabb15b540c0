"""The impulse the frame receives at an impact, in the events table and the report rows.

The physics of the impulse (the momentum jump of the mechanism equals minus the frame's
impulse) is tested in tests/physics/test_frame_loads_press_cycle.py; here: that the tables
carry it, with zeros for events without one."""

from types import SimpleNamespace as E

import numpy as np

from mechdyn.results.events import events_table
from mechdyn.results.report_events import events_rows, merged_events

MODE = frozenset({"pin@contact"})


def _events():
    common = dict(mode_before=frozenset({"s@up"}), mode_after=MODE, energy_lost=2.0,
                  message="", q_after=np.array([0.1]))
    return [E(t=0.05, kind="separate", element="s@low", mode_before=frozenset(),
              mode_after=frozenset({"s@up"}), energy_lost=0.0, message="",
              q_after=np.array([0.0]), impulses={}),
            E(t=0.1, kind="impact", element="pin@contact",
              impulses={"pin@contact": 4.0, "frame": np.array([-2.5, 0.5, 0.1])}, **common),
            E(t=0.1, kind="impact", element="s@up",
              impulses={"s@up": 1.0, "frame": np.array([-2.5, 0.5, 0.1])}, **common)]


def test_the_events_table_carries_the_frame_impulse():
    df = events_table(_events(), ["phi"])
    assert df[["Jx_frame_Ns", "Jy_frame_Ns", "H_frame_Nms"]].to_numpy().tolist() == [
        [0.0, 0.0, 0.0], [-2.5, 0.5, 0.1], [-2.5, 0.5, 0.1]]


def test_a_merged_transition_counts_its_frame_impulse_once():
    merged = merged_events(_events())
    assert [t.frame_impulse for t in merged] == [None, (-2.5, 0.5, 0.1)]
    rows = events_rows(merged, ["phi"], [True])
    assert [r["frame impulse x (N s)"] for r in rows] == [0.0, -2.5]
    assert rows[1]["frame impulse y (N s)"] == 0.5


def test_a_run_without_impacts_has_no_impulse_columns_in_the_report():
    rows = events_rows(merged_events(_events()[:1]), ["phi"], [True])
    assert "frame impulse x (N s)" not in rows[0]
