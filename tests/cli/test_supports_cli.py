"""``mechdyn supports`` end to end, through ``mechdyn.cli.main``."""

import csv

import numpy as np
import pytest

from mechdyn.cli import main


def test_a_two_span_beam_lifts_off_its_far_support(tmp_path, capsys):
    out_csv = tmp_path / "s.csv"
    rc = main(["supports", "--at", "0m,3m,6m", "--EI", "2MN*m^2", "--load", "1.2m:10kN",
               "-o", str(out_csv)])
    out = capsys.readouterr().out
    assert rc == 0 and "open (lifted off)" in out
    rows = list(csv.DictReader(out_csv.open()))
    a, b, L, P, EI = 1.2, 1.8, 3.0, 1e4, 2e6
    # simply supported span AB, an unloaded overhang rising by P a (L^2 - a^2) / (6 EI)
    np.testing.assert_allclose([float(r["force_N"]) for r in rows], [P * b / L, P * a / L, 0],
                               rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(float(rows[2]["gap_mm"]), 1e3 * P * a * (L * L - a * a)
                               / (6 * EI), rtol=1e-12)
    assert [r["closed"] for r in rows] == ["1", "1", "0"]


def test_held_down_supports_of_a_rigid_beam_on_springs(capsys):
    rc = main(["supports", "--at", "0m,1.5m,4m", "--stiffness", "2e6N/m,5N/um,3kN/mm",
               "--load", "0.3m:10kN", "--bilateral"])
    out = capsys.readouterr().out
    assert rc == 0 and "lifted off" not in out
    k, x = np.array([2e6, 5e6, 3e6]), np.array([0.0, 1.5, 4.0])
    s0, s1, s2 = k.sum(), k @ x, k @ x ** 2
    w0, phi = np.linalg.solve([[s0, s1], [s1, s2]], [1e4, 1e4 * 0.3])
    lam3 = k[2] * (w0 + phi * x[2])
    assert lam3 < 0 and f"{lam3:.6g}" in out


@pytest.mark.parametrize("argv, msg", [
    (["--at", "0m,1m", "--stiffness", "1e6N/m", "--load", "0.5m:1kN"], "expected 2 value"),
    (["--at", "0m,1m", "--EI", "3kg", "--load", "0.5m:1kN"], "bending stiffness"),
    (["--at", "0m,1m", "--load", "0.5m"], "POSITION:FORCE"),
    (["--at", "0m,1m,2m", "--stiffness", "1e6,-5,rigid", "--load", "0.5m:1kN"],
     "support(s) [2] (numbered from 1)"),
    (["--at", "0m,1m", "--EI", "-3", "--load", "0.5m:1kN"], "leave --EI out"),
    (["--at", "0m,1m,2m", "--load", "0.5m:1kN"], "not unique"),
    (["--at", "0m,1m", "--stiffness", "1e6N/m,1e6N/m", "--load", "2m:1kN"], "tips over|holds"),
])
def test_bad_input_is_a_clear_error(argv, msg, capsys):
    assert main(["supports", *argv]) == 2
    err = capsys.readouterr().err
    assert "mechdyn supports: error:" in err
    assert any(m in err for m in msg.split("|"))
