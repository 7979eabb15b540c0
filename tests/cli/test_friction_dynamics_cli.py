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


def test_simulate_csv_has_the_friction_work_and_power(tmp_path, capsys):
    """The block sliding down the incline loses mu m g cos(a) |v| to friction, W, and
    has lost mu m g cos(a) |s| by then, J (v = acc t, s = acc t^2 / 2): columns
    W_friction_J and P_friction_W of the CSV, with their units in the header."""
    model = tmp_path / "block.toml"
    model.write_text(_model(DEG, MU), encoding="utf-8")
    csv = tmp_path / "run.csv"
    assert main(["simulate", str(model), "--t-end", "0.3s", "--samples", "7", "-o",
                 str(csv)]) == 0
    capsys.readouterr()
    head = [ln for ln in csv.read_text(encoding="utf-8").splitlines() if ln.startswith("#")]
    assert any("W_friction_J [J]" in ln and "P_friction_W [W]" in ln for ln in head)
    df = pd.read_csv(csv, comment="#")
    a = np.deg2rad(DEG)
    acc = G * (np.sin(a) - MU * np.cos(a))
    normal = MU * 2.0 * G * np.cos(a)
    t = df["t_s"]
    np.testing.assert_allclose(df["P_friction_W"], normal * acc * t, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(df["W_friction_J"], normal * acc * t**2 / 2, rtol=1e-9,
                               atol=1e-12)
