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


def _csv(path, rows):
    path.write_text("\n".join(",".join(repr(float(v)) for v in row) for row in rows) + "\n")
    return str(path)


def test_general_problem_from_csv_files_matches_the_closed_form(tmp_path, capsys):
    # a rigid block (one sinking u) on three springs k1 = k2 = 1e6, k3 = 2e6 N/m, the third
    # with 1 mm clearance, 3 kN: with all closed, k1 u + k2 u + k3 (u - g) = W
    C = _csv(tmp_path / "C.csv", [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 0.5e-6]])
    A = _csv(tmp_path / "A.csv", [[1], [1], [1]])
    out_csv = tmp_path / "s.csv"
    rc = main(["supports", "--compliance", C, "--gap", "0mm,0mm,1mm", "--equilibrium", A,
               "--resultant", "3kN", "-o", str(out_csv)])
    assert rc == 0
    k, g, W = np.array([1e6, 1e6, 2e6]), np.array([0, 0, 1e-3]), 3e3
    u = (W + k[2] * g[2]) / k.sum()
    rows = list(csv.DictReader(out_csv.open()))
    np.testing.assert_allclose([float(r["force_N"]) for r in rows], k * (u - g), rtol=1e-12)
    assert f"{u:.6g}" in capsys.readouterr().out
    # with 3 mm clearance the third spring stays open: the two others share the load
    rc = main(["supports", "--compliance", C, "--gap", "0mm,0mm,3mm", "--equilibrium", A,
               "--resultant", "3000", "-o", str(out_csv)])
    rows = list(csv.DictReader(out_csv.open()))
    np.testing.assert_allclose([float(r["force_N"]) for r in rows], [1500, 1500, 0], atol=1e-9)
    assert [r["closed"] for r in rows] == ["1", "1", "0"]
    np.testing.assert_allclose(float(rows[2]["gap_mm"]), 3.0 - 1.5, rtol=1e-12)


def test_general_problem_with_load_gaps_and_no_rigid_motion(tmp_path):
    # two supports held elsewhere: the loads open gaps of -1 mm and +1 mm (a pull on the
    # second): the first closes with 1 mm / 1e-6 m/N = 1 kN, the second stays open
    C = _csv(tmp_path / "C.csv", [[1e-6, 0], [0, 1e-6]])
    q = _csv(tmp_path / "q.csv", [[-1e-3], [1e-3]])
    out_csv = tmp_path / "s.csv"
    assert main(["supports", "--compliance", C, "--load-gaps", q, "-o", str(out_csv)]) == 0
    rows = list(csv.DictReader(out_csv.open()))
    np.testing.assert_allclose([float(r["force_N"]) for r in rows], [1e3, 0], atol=1e-9)


@pytest.mark.parametrize("files, argv, msg", [
    ({"C": [[1, 2], [2, 1]]}, [], "not positive semidefinite"),
    ({"C": [[1], [1]]}, [], "square"),
    ({"C": [[1e-6, 0], [0, 1e-6]], "A": [[1], [1], [1]]}, ["--resultant", "1kN"],
     "expected a 2x1 table"),
    ({"C": [[1e-6, 0], [0, 1e-6]], "A": [[1], [1]]}, [], "go together"),
    ({"C": [[1e-6, 0], [0, 1e-6]], "A": [[1], [1]]}, ["--resultant", "3kg"], "a force"),
    ({"C": [[1e-6, 0], [0, 1e-6]]}, ["--load", "1m:1kN"], "goes with --at"),
    ({"C": [[1e-6, 0], [0, 1e-6]]}, ["--gap", "1mm"], "expected 2 value"),
])
def test_bad_general_input_is_a_clear_error(tmp_path, capsys, files, argv, msg):
    args = ["supports", "--compliance", _csv(tmp_path / "C.csv", files["C"]), *argv]
    if "A" in files:
        args += ["--equilibrium", _csv(tmp_path / "A.csv", files["A"])]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "mechdyn supports: error:" in err and msg in err


def test_a_compliance_file_that_is_not_numbers_is_named(tmp_path, capsys):
    bad = tmp_path / "C.csv"
    bad.write_text("1e-6, x\n0, 1e-6\n")
    assert main(["supports", "--compliance", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "--compliance" in err and "not a table of numbers" in err
    assert main(["supports", "--at", "0m,1m", "--load", "0.5m:1kN", "--equilibrium",
                 str(bad)]) == 2
    assert "goes with --compliance" in capsys.readouterr().err
