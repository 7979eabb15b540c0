"""``mechdyn kinetostatics`` with friction in a pin: the loss and efficiency columns and
the cycle-efficiency line, against the closed form of a crank turning under gravity."""

import numpy as np
import pandas as pd

from mechdyn.cli import main

M, A, G, MU, R_PIN, RPM = 2.0, 0.1, 9.81, 0.1, 0.015, 60.0
PIN = f'"{R_PIN * 1000} mm"'

CRANK_TOML = f"""
[model]
name = "crank with pin friction"
gravity = ["0 m/s^2", "-{G} m/s^2"]

[bodies]
crank = {{ mass = "{M} kg", inertia = "0.01 kg*m^2", com = ["{A * 1000} mm", "0 mm"] }}

[joints]
O = {{ type = "revolute", parent = "ground", child = "crank", friction = {MU}, pin_radius = {PIN} }}

[coordinates]
phi = {{ kind = "angle", body = "crank" }}
"""


def test_pin_friction_columns_and_cycle_efficiency(tmp_path, capsys):
    model = tmp_path / "crank.toml"
    model.write_text(CRANK_TOML, encoding="utf-8")
    csv = tmp_path / "forces.csv"
    rc = main(["kinetostatics", str(model), "--speed", f"{RPM}rpm", "--from", "0deg",
               "--to", "360deg", "--steps", "37", "-o", str(csv)])
    assert rc == 0
    out = capsys.readouterr().out
    assert "cycle efficiency" in out and "energy lost per pair: O" in out
    df = pd.read_csv(csv)
    # closed form: the pin carries R = m (a_G - g) (centripetal acceleration of the
    # centre of mass at constant speed); the drive holds the weight's moment and the
    # friction moment mu r |R| against the rotation
    w = RPM * 2 * np.pi / 60
    phi = np.deg2rad(df["phi_deg"].to_numpy())
    R = M * np.stack([-w**2 * A * np.cos(phi), -w**2 * A * np.sin(phi) + G], axis=-1)
    Rm = np.hypot(R[:, 0], R[:, 1])
    T = M * G * A * np.cos(phi) + MU * R_PIN * Rm
    np.testing.assert_allclose(df["M_drive_phi_Nm"], T, rtol=0, atol=1e-10 * np.abs(T).max())
    np.testing.assert_allclose(df["P_loss_O_W"], MU * R_PIN * Rm * w, rtol=1e-10)
    np.testing.assert_allclose(df["P_out_W"], M * G * A * np.cos(phi) * w, atol=1e-10)
    assert {"P_loss_W", "efficiency", "self_locked"} <= set(df.columns)
