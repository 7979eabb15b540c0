"""``mechdyn foundation`` through its own parser (the subcommand module's register/run)."""

import argparse

import numpy as np
import pytest

from mechdyn.cli import foundation as cli
from mechdyn.errors import ModelError
from mechdyn.foundation import AnchorBolt, Isolator
from mechdyn.results.table import read_csv

BOLTS = ["b1: x=-0.3m, y=-0.1m, k_axial=2e8N/m, k_shear=1e8N/m, preload=200N",
         "b2: x=0.4m, y=-0.1m, k_axial=2e8N/m, k_shear=1e8N/m, preload=200N"]


def _args(*argv):
    parser = argparse.ArgumentParser(prog="mechdyn")
    sub = parser.add_subparsers(dest="command")
    cli.register(sub)
    return parser.parse_args(["foundation", *argv])


def test_bolts_and_mounts_from_the_command_line(tmp_path, capsys):
    out, png = tmp_path / "loads.csv", tmp_path / "loads.png"
    argv = ["slider_crank", "--t-end", "0.05s", "--samples", "101", "-o", str(out),
            "--plot", str(png), "--mass", "50kg", "--inertia", "2kg*m^2", "--speed", "400rpm",
            "--weight",
            "--isolator", "m1: x=0m, y=-0.1m, kx=1e5N/m, ky=2e5N/m, cy=300N*s/m"]
    for b in BOLTS:
        argv += ["--support", b]
    assert cli.run(_args(*argv)) == 0
    text = capsys.readouterr().out
    assert "b1: |F| max" in text and "natural frequencies of the mounted base" in text
    df = read_csv(out)
    assert {"N_b1_N", "V_b1_N", "clamp_b2_N", "Fx_m1_N", "Fy_m1_N"} <= set(df.columns)
    total = df["Fy_m1_N"] + df["Fy_b1_N"] + df["Fy_b2_N"]
    np.testing.assert_allclose(df["clamp_b1_N"], 200.0 - df["Fy_b1_N"], rtol=1e-10, atol=1e-8)
    np.testing.assert_allclose(total, df["Fy_base_N"], rtol=0,
                               atol=1e-10 * np.max(np.abs(df["Fy_base_N"])))
    assert (tmp_path / "loads_mounted.csv").is_file() and png.stat().st_size > 0


def test_a_support_text_is_read_with_units_and_checked():
    iso = cli.parse_support("m1: x=50cm, y=0m, kx=2N/mm, ky=5e5N/m, cy=2kN*s/m", Isolator,
                            "--isolator")
    assert (iso.x, iso.kx, iso.cy) == (0.5, 2000.0, 2000.0)
    with pytest.raises(ModelError, match="--support b1: missing k_shear"):
        cli.parse_support("b1: x=0m, y=0m, k_axial=1e8N/m", AnchorBolt, "--support")
    with pytest.raises(ModelError, match="unknown field 'k_axail'"):
        cli.parse_support("b1: x=0m, y=0m, k_axail=1e8N/m", AnchorBolt, "--support")
    with pytest.raises(ModelError, match="expected NAME: key=value"):
        cli.parse_support("x=0m", AnchorBolt, "--support")
    with pytest.raises(ModelError, match="give the supports"):
        cli.run(_args("slider_crank", "--t-end", "0.01s"))
