"""The model-file tables of switches, stops, contacts and coordinate locks."""

import numpy as np

from mechdyn.mechanism import Mechanism
from mechdyn.modelfile.switches import parse_switches


def _mech():
    m = Mechanism("slider", gravity=(0.0, 0.0))
    m.add_body("mass", mass=1.0, inertia=0.1, points={"tip": (0.01, 0.0)})
    m.add_prismatic("slide", "ground", "mass", axis=(1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="slide")
    return m


def test_tables_are_read_with_units():
    doc = {
        "coordinate_locks": [{"name": "hold", "variable": "s", "frees": ["s"]}],
        "stops": [{"name": "st", "variable": "joint:slide", "lower": "-5 mm",
                   "restitution": 0.5}],
        "contacts": [{"name": "c", "body": "mass", "point": "tip", "line_body": "ground",
                      "line_point": ["20 mm", "0 mm"], "line_direction": [0, -1],
                      "friction": 0.2}],
        "switches": [{"name": "on", "action": "engage", "target": "hold", "variable": "s",
                      "value": "3 mm", "direction": "falling",
                      "guard": [["s_dot", "<", "0 m/s"]]},
                     {"name": "off", "action": "release", "target": "hold",
                      "times": ["0.1 s", "200 ms"]}],
    }
    m = _mech()
    assert parse_switches(doc, m, "f.toml") == []
    st = m.extras["stops"][0]
    assert st.lower == -0.005 and st.restitution == 0.5
    sw = {s.name: s for s in m.extras["switches"]}
    assert sw["on"].value == 0.003 and sw["on"].direction == -1
    assert sw["on"].guard == (("s_dot", "<", 0.0),)
    np.testing.assert_allclose(sw["off"].times, (0.1, 0.2))
    assert m.extras["contacts"][0].line_point == (0.02, 0.0)


def test_every_problem_is_reported_with_file_table_and_key():
    doc = {
        "stops": [{"name": "st", "variable": "joint:nope", "lower": "1 kg"}],
        "switches": [{"name": "on", "action": "grab", "target": "hodl", "times": ["1 m"]}],
        "contacts": [{"name": "c", "body": "mas", "point": [0, 0], "line_body": "ground"}],
    }
    probs = parse_switches(doc, _mech(), "f.toml")
    text = "\n".join(probs)
    assert "f.toml: [[stops]] #1 'st' variable" in text and "'slide'" in text
    assert "[[switches]] #1 'on' action" in text
    assert "valid lock names" in text
    assert "[[contacts]] #1 'c' body" in text and "'mass'" in text
    assert len(probs) >= 5
