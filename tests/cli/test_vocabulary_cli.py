"""One spelling per meaning on the command line (issue 14, item 10): ``--moment-point X,Y``
(the point moments are taken about), ``--mass-at BODY.POINT`` (reduce), ``--engage
LOCK[,LOCK]`` (the engaged locks, ``none`` for none); the old spellings ``--point`` and
``--mode`` still work but are not shown in ``--help``."""

import argparse
import re

import numpy as np
import pytest

from mechdyn.cli import main
from mechdyn.cli.options import engage_from_args
from mechdyn.errors import ModelError
from mechdyn.results.table import read_csv


def _help(capsys, command):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    return capsys.readouterr().out


def _options(text):
    return set(re.findall(r"(?<![\w-])--[a-z][\w-]*", text))


@pytest.mark.parametrize("command, shown, hidden", [
    ("kinetostatics", {"--moment-point", "--engage"}, {"--point", "--mode"}),
    ("reduce", {"--mass-at", "--engage"}, {"--point", "--mode"}),
    ("flywheel", {"--engage"}, {"--point", "--mode"}),
    ("simulate", {"--moment-point", "--engage", "--fixed-steps"}, {"--point", "--mode",
                                                                   "--steps"}),
])
def test_help_shows_only_the_new_spelling(capsys, command, shown, hidden):
    options = _options(_help(capsys, command))
    assert shown <= options
    assert not hidden & options


def test_moment_point_and_its_old_spelling_transfer_the_moment(tmp_path):
    """M about P = M about O - (xP Fy - yP Fx): the transfer of a moment, checked on the
    table each spelling writes."""
    base = ["kinetostatics", "toggle_press", "--speed", "40rpm", "--steps", "7",
            "--harmonics", "0", "-o"]
    o, p, old = tmp_path / "o.csv", tmp_path / "p.csv", tmp_path / "old.csv"
    assert main([*base, str(o)]) == 0
    assert main([*base, str(p), "--moment-point", "100mm,-50mm"]) == 0
    assert main([*base, str(old), "--point", "100mm,-50mm"]) == 0
    o, p, old = read_csv(o), read_csv(p), read_csv(old)
    expected = o["M_frame_Nm"] - (0.1 * o["Fy_frame_N"] - (-0.05) * o["Fx_frame_N"])
    np.testing.assert_allclose(p["M_frame_Nm"], expected, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(old["M_frame_Nm"], p["M_frame_Nm"], rtol=0, atol=0)


def test_simulate_takes_the_moment_point(tmp_path):
    base = ["simulate", "clutchless_press", "--t-end", "5ms", "--samples", "6",
            "--backend", "numpy", "--no-progress", "-o"]
    o, p = tmp_path / "o.csv", tmp_path / "p.csv"
    assert main([*base, str(o)]) == 0
    assert main([*base, str(p), "--moment-point", "100mm,0mm"]) == 0
    o, p = read_csv(o), read_csv(p)
    np.testing.assert_allclose(p["M_frame_Nm"], o["M_frame_Nm"] - 0.1 * o["Fy_frame_N"],
                               rtol=1e-9, atol=1e-9)


def test_simulate_engages_a_lock_at_the_start(tmp_path):
    """The rocker locked to the slider: psi keeps its initial value."""
    out = tmp_path / "locked.csv"
    assert main(["simulate", "clutchless_press", "--t-end", "10ms", "--samples", "6",
                 "--backend", "numpy", "--no-progress", "--engage", "rocker_lock",
                 "-o", str(out)]) == 0
    psi = read_csv(out)["psi_rad"].to_numpy()
    np.testing.assert_allclose(psi, psi[0], atol=1e-12)


@pytest.mark.parametrize("old", [False, True])
def test_engage_and_its_old_spelling_in_kinetostatics(old, capsys):
    flag = "--mode" if old else "--engage"
    rc = main(["kinetostatics", "clutchless_press", "--speed", "43.5rad/s", "--steps", "7",
               "--harmonics", "0", flag, "rocker_lock"])
    assert rc == 0
    assert "redundant" in capsys.readouterr().out  # the lock closes a loop: not unique


def test_engage_an_unknown_lock_names_the_valid_ones(capsys):
    rc = main(["kinetostatics", "clutchless_press", "--speed", "43.5rad/s", "--steps", "7",
               "--engage", "rocker_lok=0mm,0mm,0deg"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "rocker_lok" in err and "rocker_lock" in err


def test_engage_none_is_alone(capsys):
    rc = main(["reduce", "slider_crank", "--engage", "none,rocker_lock"])
    assert rc == 2
    assert "'none'" in capsys.readouterr().err


def test_engage_reads_names_poses_and_none():
    def read(*specs):
        return engage_from_args(argparse.Namespace(engage=list(specs)))

    names, poses = read("a,b=100mm,0,90deg", "c")
    assert names == {"a", "b", "c"}
    assert set(poses) == {"b"}
    np.testing.assert_allclose(poses["b"], (0.1, 0.0, np.pi / 2))
    assert read("none") == (frozenset(), {})
    assert read("NONE") == (frozenset(), {})
    assert engage_from_args(argparse.Namespace(engage=None)) == (None, {})
    with pytest.raises(ModelError, match="X,Y,THETA"):
        read("b=1mm,2mm")


def test_mass_at_and_its_old_spelling(tmp_path, capsys):
    """m_red at the crank pin is J_red / r^2 (r = 50 mm), under either spelling."""
    new, old = tmp_path / "new.csv", tmp_path / "old.csv"
    assert main(["reduce", "slider_crank", "--steps", "13", "--mass-at", "crank.A",
                 "-o", str(new)]) == 0
    assert "m_red at crank.A" in capsys.readouterr().out
    assert main(["reduce", "slider_crank", "--steps", "13", "--point", "crank.A",
                 "-o", str(old)]) == 0
    new, old = read_csv(new), read_csv(old)
    np.testing.assert_allclose(new["m_red_kg"] * 0.05**2, new["J_red_kgm2"], rtol=1e-9)
    np.testing.assert_array_equal(new["m_red_kg"], old["m_red_kg"])
    assert main(["reduce", "slider_crank", "--mass-at", "crank.Q"]) == 2
    assert "valid point names: 'com', 'A'" in capsys.readouterr().err
    assert main(["reduce", "slider_crank", "--mass-at", "crankA"]) == 2
    assert "--mass-at 'crankA': write it as BODY.POINT" in capsys.readouterr().err


def test_reduce_engages_a_list_of_locks(capsys):
    """``--engage LOCK=POSE`` in one comma list, as in kinetostatics."""
    rc = main(["reduce", "clutchless_press", "--engage", "rocker_lock=0mm,0mm,0deg",
               "--drop", "psi", "--steps", "13"])
    assert rc == 0
    assert "reduction to coordinate 'phi'" in capsys.readouterr().out


def test_fixed_steps_and_its_old_spelling(tmp_path):
    """``--steps`` counts positions of a sweep everywhere; the steps of wilson / rk4 are
    ``--fixed-steps`` (N steps: N + 1 rows, ends included)."""
    new, old = tmp_path / "new.csv", tmp_path / "old.csv"
    base = ["simulate", "slider_crank", "--t-end", "10ms", "--integrator", "rk4",
            "--backend", "numpy", "--no-progress"]
    assert main([*base, "--fixed-steps", "10", "-o", str(new)]) == 0
    assert main([*base, "--steps", "10", "-o", str(old)]) == 0
    new, old = read_csv(new), read_csv(old)
    assert len(new) == 11
    np.testing.assert_allclose(np.diff(new["t_s"]), 1e-3, rtol=1e-9)
    np.testing.assert_array_equal(new["phi_rad"], old["phi_rad"])
