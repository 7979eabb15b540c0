"""``mechdyn simulate``: runs, output files, exit codes and messages."""

import numpy as np
import pandas as pd
import pytest

from mechdyn.cli import main


def test_andrews_to_csv(tmp_path, capsys):
    out = tmp_path / "andrews.csv"
    code = main(["simulate", "andrews_squeezer", "--t-end", "10 ms", "--rtol", "1e-10",
                 "-o", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "status: success" in text
    assert "evaluations" in text and "balance" in text
    df = pd.read_csv(out, comment="#")
    assert df["t_s"].iloc[-1] == pytest.approx(0.01)
    for col in ("beta_rad", "beta_deg", "beta_dot_rad_s", "beta_ddot_rad_s2", "theta_rod_rad",
                "omega_rod_rad_s", "x_rod_m", "vx_rod_m_s", "T_J", "U_J", "W_nc_J",
                "E_balance_J"):
        assert col in df.columns, col
    assert np.ptp(df["E_balance_J"]) < 1e-8


def test_press_wilson_40_steps_with_drive_and_plot(tmp_path, capsys):
    out, png = tmp_path / "press.csv", tmp_path / "press.png"
    code = main(["simulate", "clutchless_press", "--t-end", "30 ms", "--integrator", "wilson",
                 "--steps", "40", "--drive", "phi=34.5 N*m", "--points",
                 "-o", str(out), "--plot", str(png)])
    assert code == 0, capsys.readouterr()
    df = pd.read_csv(out, comment="#")
    assert len(df) == 41
    assert {"phi_deg", "psi_deg", "x_rocker_B_m", "vx_rocker_B_m_s", "ax_rocker_B_m_s2"} <= \
        set(df.columns)
    assert df["phi_deg"].iloc[0] == pytest.approx(-64.1)
    assert png.stat().st_size > 1000


def test_stopped_run_exits_1_and_keeps_data(tmp_path, capsys):
    # without the ram's support the free ram falls and the mechanism reaches the position
    # where the rod is normal to the ram axis (singular for phi, psi) just before 0.05 s
    out = tmp_path / "stop.csv"
    code = main(["simulate", "clutchless_press", "--t-end", "0.06", "--drive", "phi=34.5",
                 "--integrator", "rk4", "--fixed-steps", "240", "-o", str(out)])
    assert code == 1
    cap = capsys.readouterr()
    assert "singular-position" in cap.out and "stopped early" in cap.err
    df = pd.read_csv(out, comment="#")
    assert 0.04 < df["t_s"].iloc[-1] < 0.06


def test_bad_integrator_is_exit_2(capsys):
    code = main(["simulate", "andrews_squeezer", "--t-end", "0.01", "--integrator", "euler"])
    assert code == 2
    err = capsys.readouterr().err
    assert "unknown integrator 'euler'" in err and "dop853" in err


@pytest.mark.parametrize("args, match", [
    (["--t-end", "-1 s"], "t_end"),
    (["--t-end", "0.01", "--integrator", "wilson", "--fixed-steps", "0"], "steps"),
    (["--t-end", "0.01", "--integrator", "wilson", "--fixed-steps", "10", "--theta", "1.2"],
     "theta"),
    (["--t-end", "0.01", "--rtol", "0"], "rtol"),
    (["--t-end", "5 kg"], "time"),
    (["--t-end", "0.01", "--drive", "gamma=1"], "coordinate"),
])
def test_bad_options_are_exit_2(args, match, capsys):
    code = main(["simulate", "andrews_squeezer", *args])
    assert code == 2
    assert match in capsys.readouterr().err


def test_switching_run_writes_its_events_beside_the_table(tmp_path, capsys):
    out = tmp_path / "press.csv"
    code = main(["simulate", "press_cycle", "--t-end", "0.02 s", "--integrator", "rk4",
                 "--dt", "1ms", "-o", str(out)])
    assert code == 0, capsys.readouterr()
    ev = pd.read_csv(tmp_path / "press_events.csv")
    assert list(ev.columns) == ["t_s", "kind", "element", "mode_before", "mode_after",
                                "energy_lost_J", "Jx_frame_Ns", "Jy_frame_Ns", "H_frame_Nms",
                                "phi_after", "psi_after", "p_after"]
    assert ("close", "ram_stop@upper") in set(zip(ev["kind"], ev["element"], strict=True))


def test_ctrl_c_writes_the_samples_so_far_and_exits_130(tmp_path, capsys, monkeypatch):
    """Ctrl-C in the middle of a run: no traceback, the samples computed so far are
    written, status "interrupted", exit code 130."""
    from mechdyn.dynamics.mode_system import ModeSystem

    calls = {"n": 0}
    evaluate = ModeSystem.evaluate

    def interrupted_later(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] > 400:
            raise KeyboardInterrupt
        return evaluate(self, *args, **kwargs)

    monkeypatch.setattr(ModeSystem, "evaluate", interrupted_later)
    out = tmp_path / "press.csv"
    code = main(["simulate", "clutchless_press", "--t-end", "1 s", "--backend", "numpy",
                 "-o", str(out)])
    captured = capsys.readouterr()
    assert code == 130
    assert "interrupted" in captured.out and "Traceback" not in captured.err
    df = pd.read_csv(out, comment="#")
    assert len(df) > 5 and 0.0 < df["t_s"].iloc[-1] < 1.0


@pytest.mark.parametrize(("option", "value", "why"), [
    ("-o", "", "the path is empty"),
    ("--plot", "out.txt", "unknown image type '.txt'"),
    ("-o", ".", "is a folder"),
])
def test_output_paths_are_checked_before_the_run(option, value, why, tmp_path, capsys,
                                                 monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = main(["simulate", "clutchless_press", "--t-end", "1 ms", option, value])
    err = capsys.readouterr().err
    assert code == 2 and why in err and "Traceback" not in err


@pytest.mark.skipif(not __import__("os").path.exists("/dev/full"), reason="needs /dev/full")
def test_a_full_disk_is_a_named_error(capsys):
    code = main(["simulate", "clutchless_press", "--t-end", "1 ms", "-o", "/dev/full"])
    err = capsys.readouterr().err
    assert code == 2 and "cannot write the output" in err and "Traceback" not in err


def test_sigterm_writes_the_samples_so_far_atomically_and_exits_143(tmp_path, capsys,
                                                                     monkeypatch):
    """SIGTERM ends a run as Ctrl-C does (exit 143); the table replaces an older one only
    once written completely."""
    import os
    import signal

    from mechdyn.dynamics.mode_system import ModeSystem

    calls = {"n": 0}
    evaluate = ModeSystem.evaluate

    def terminated_later(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 300:
            os.kill(os.getpid(), signal.SIGTERM)
        return evaluate(self, *args, **kwargs)

    monkeypatch.setattr(ModeSystem, "evaluate", terminated_later)
    out = tmp_path / "press.csv"
    out.write_text("stale\n")
    code = main(["simulate", "clutchless_press", "--t-end", "1 s", "--backend", "numpy",
                 "-o", str(out)])
    assert code == 143
    df = pd.read_csv(out, comment="#")
    assert len(df) > 5 and df["t_s"].iloc[-1] < 1.0
    assert not list(tmp_path.glob(".*part*"))  # no temporary file left


def test_the_table_is_a_uniform_grid_by_default_and_steps_on_request(tmp_path, capsys):
    out = tmp_path / "fb.csv"
    assert main(["simulate", "four_bar", "--t-end", "0.1 s", "-o", str(out)]) == 0
    t = pd.read_csv(out, comment="#")["t_s"].to_numpy()
    assert t.size == 1001 and np.allclose(np.diff(t), 1e-4)
    assert main(["simulate", "four_bar", "--t-end", "0.1 s", "--every-step", "-o",
                 str(out)]) == 0
    assert 2 < len(pd.read_csv(out, comment="#")) < 200  # the integrator's own steps


def test_sigint_to_a_running_command_keeps_the_samples_marked_interrupted(tmp_path):
    """The acceptance run: ``mechdyn simulate press_cycle --t-end 2s -o out.csv`` stopped by
    SIGINT after 4 s exits 130 without a traceback; out.csv holds the samples computed so
    far and its header says the run was interrupted."""
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    out = tmp_path / "out.csv"
    proc = subprocess.Popen(
        [sys.executable, "-c", "import sys; from mechdyn.cli import main; sys.exit(main())",
         "simulate", "press_cycle", "--t-end", "2s",
         "--backend", "numpy", "--no-progress", "-o", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # wait for 4 s of the child's own CPU time (not wall time: on a loaded machine the
    # child may still be importing after 4 s), at most 90 s of wall time
    deadline = time.monotonic() + 90.0
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            fields = Path(f"/proc/{proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
            cpu = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        except (OSError, IndexError, ValueError):  # no /proc: fall back to wall time
            cpu = 4.0 if time.monotonic() > deadline - 86.0 else 0.0
        if cpu >= 4.0:
            break
        time.sleep(0.1)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, (stdout, stderr)
    assert "Traceback" not in stderr
    text = out.read_text()
    assert "# status: interrupted" in text
    df = pd.read_csv(out, comment="#")
    assert len(df) > 2 and df["t_s"].iloc[-1] < 2.0


def test_the_spectrum_of_a_column(tmp_path, capsys):
    out, png = tmp_path / "fb.csv", tmp_path / "fb.png"
    assert main(["simulate", "four_bar", "--t-end", "1s", "--spectrum", "Fy_frame_N",
                 "-o", str(out), "--plot", str(png)]) == 0
    text = capsys.readouterr().out
    assert "Fy_frame_N: peak" in text and "dominant components" in text
    sp = pd.read_csv(tmp_path / "fb_spectrum.csv")
    assert {"f_Hz", "amplitude"} <= set(sp.columns)
    assert (tmp_path / "fb_spectrum.png").stat().st_size > 1000
    assert main(["simulate", "four_bar", "--t-end", "0.1s", "--spectrum", "Fz_frame_N"]) == 2
    assert "--spectrum: unknown column 'Fz_frame_N'; valid column names" in capsys.readouterr().err
