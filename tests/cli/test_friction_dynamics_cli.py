"""``mechdyn simulate`` of a model file with friction in a guide: the stick and slip events
in the events table, and the motion against the closed form g (sin a - mu cos a)."""

import numpy as np
import pandas as pd

from mechdyn.cli import main

G, MU, DEG = 9.81, 0.3, 30.0  # tan 30 deg = 0.577 > mu: the block slides down


def _model(deg, mu):
    return f"""
[model]
name = "block on a rough incline"
gravity = ["0 m/s^2", "-{G} m/s^2"]

[bodies]
block = {{ mass = "2 kg", inertia = "0.01 kg*m^2", pose = ["0 mm", "0 mm", "{deg} deg"] }}

[joints.guide]
type = "prismatic"
parent = "ground"
child = "block"
axis = "{deg} deg"
friction = {mu}
guide_length = "50 mm"

[coordinates]
s = {{ kind = "travel", joint = "guide" }}
"""


def test_simulate_a_block_that_slides_and_one_that_sticks(tmp_path, capsys):
    for deg, mu, state in ((DEG, MU, "slip-"), (10.0, MU, "stick")):
        model = tmp_path / "block.toml"
        model.write_text(_model(deg, mu), encoding="utf-8")
        csv = tmp_path / "run.csv"
        rc = main(["simulate", str(model), "--t-end", "0.3s", "--samples", "7", "-o", str(csv)])
        assert rc == 0
        events = pd.read_csv(tmp_path / "run_events.csv", comment="#")
        assert events.iloc[0].astype(str).str.contains(state).any()
        df = pd.read_csv(csv, comment="#")
        a = np.deg2rad(deg)
        acc = -G * (np.sin(a) - mu * np.cos(a)) if state != "stick" else 0.0
        np.testing.assert_allclose(df["s_m"], 0.5 * acc * df["t_s"] ** 2, rtol=0, atol=1e-10)
    capsys.readouterr()
