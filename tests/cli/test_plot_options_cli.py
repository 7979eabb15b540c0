"""``--plot-columns`` (simulate, kinematics, kinetostatics) and ``--plot-polar``
(kinetostatics) on the command line."""

import pytest

from mechdyn.cli import main


def test_kinematics_plots_the_chosen_columns(tmp_path, capsys):
    png = tmp_path / "cols.png"
    rc = main(["kinematics", "slider_crank", "--speed", "100rpm", "--steps", "73",
               "--plot", str(png), "--plot-columns", "phi_deg,omega_rod_rad_s"])
    assert rc == 0
    assert png.stat().st_size > 1000
    assert f"plot: {png}" in capsys.readouterr().out


def test_an_unknown_column_is_an_error_listing_the_valid_ones(tmp_path, capsys):
    png = tmp_path / "cols.png"
    rc = main(["kinematics", "slider_crank", "--steps", "13", "--plot", str(png),
               "--plot-columns", "phi_deg,omega_nowhere_rad_s"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "--plot-columns: unknown column 'omega_nowhere_rad_s'" in err
    assert "valid column names: " in err and "'omega_rod_rad_s'" in err
    assert not png.exists()


def test_plot_columns_need_a_plot_file(capsys):
    rc = main(["kinetostatics", "slider_crank", "--speed", "10rad/s",
               "--plot-columns", "M_drive_phi_Nm"])
    assert rc == 2
    assert "--plot-columns needs --plot" in capsys.readouterr().err


@pytest.mark.parametrize("command", [
    ["simulate", "four_bar", "--t-end", "0.05s", "--samples", "51"],
    ["kinetostatics", "slider_crank", "--speed", "10rad/s", "--steps", "37"],
])
def test_simulate_and_kinetostatics_plot_the_chosen_columns(command, tmp_path):
    png = tmp_path / "cols.png"
    columns = "phi_deg,Fx_frame_N" if command[0] == "simulate" else "phi_deg,M_drive_phi_Nm"
    rc = main([*command, "--plot", str(png), "--plot-columns", columns])
    assert rc == 0
    assert png.stat().st_size > 1000


def test_kinetostatics_writes_the_polar_plots_beside_the_plot(tmp_path, capsys):
    png = tmp_path / "forces.png"
    rc = main(["kinetostatics", "slider_crank", "--speed", "10rad/s", "--steps", "37",
               "--plot", str(png), "--plot-polar", "A", "--plot-polar", "B"])
    assert rc == 0
    for joint in "AB":
        assert (tmp_path / f"forces_polar_{joint}.png").stat().st_size > 1000
    assert "polar plot of B" in capsys.readouterr().out


def test_polar_plot_of_an_unknown_joint_fails_before_the_analysis(tmp_path, capsys):
    rc = main(["kinetostatics", "slider_crank", "--speed", "10rad/s",
               "--plot", str(tmp_path / "f.png"), "--plot-polar", "Q"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "unknown joint 'Q'" in err and "'cylinder'" in err
    assert not (tmp_path / "f.png").exists()
    rc = main(["kinetostatics", "slider_crank", "--speed", "10rad/s", "--plot-polar", "A"])
    assert rc == 2
    assert "--plot-polar needs --plot" in capsys.readouterr().err


def test_animate_without_labels(tmp_path, monkeypatch):
    import mechdyn.cli.animate as cli_animate

    seen = {}
    real = cli_animate.animate

    def spy(record, path, **kwargs):
        seen.update(kwargs)
        return real(record, path, **kwargs)

    monkeypatch.setattr(cli_animate, "animate", spy)
    rc = main(["animate", "slider_crank", "--steps", "5", "--no-labels",
               "-o", str(tmp_path / "a.gif")])
    assert rc == 0 and seen["labels"] is False
    assert (tmp_path / "a.gif").stat().st_size > 1000
