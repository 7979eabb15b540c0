"""``mechdyn animate`` and ``mechdyn report`` end to end, through ``mechdyn.cli.main``."""

import re
import tomllib

from PIL import Image

from mechdyn import examples
from mechdyn.cli import main
from mechdyn.units import parse_quantity


def _crank_radius() -> float:
    """r of the bundled slider-crank, read from its model file (crank point A), m."""
    data = tomllib.loads(examples.path("slider_crank").read_text(encoding="utf-8"))
    ax, ay = (parse_quantity(v, "length") for v in data["bodies"]["crank"]["points"]["A"])
    assert ay == 0.0
    return ax


def _images(text: str) -> list[str]:
    """The kinds of the images embedded in a report (plotly.js has data URLs of its own)."""
    return re.findall(r'<img alt="[^"]*" src="data:image/(png|gif);base64,', text)


def test_animate_writes_a_gif_with_one_frame_per_position(tmp_path, capsys):
    gif, png = tmp_path / "crank.gif", tmp_path / "first.png"
    rc = main(["animate", "slider_crank", "--over", "phi", "--from", "0deg", "--to", "360deg",
               "--steps", "15", "--trace", "rod.com", "-o", str(gif), "--snapshot", str(png)])
    assert rc == 0, capsys.readouterr().err
    with Image.open(gif) as im:
        assert im.n_frames == 15
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_animate_a_short_simulation(tmp_path, capsys):
    gif = tmp_path / "run.gif"
    rc = main(["animate", "slider_crank", "--simulate", "--t-end", "5 ms", "--frames", "8",
               "-o", str(gif)])
    assert rc == 0, capsys.readouterr().err
    with Image.open(gif) as im:
        assert im.n_frames == 8


def test_animate_bad_input_is_one_line_and_exit_code_2(tmp_path, capsys):
    assert main(["animate", "slider_crank", "-o", str(tmp_path / "m.avi")]) == 2
    assert main(["animate", "slider_crank", "--trace", "rod.Q", "-o",
                 str(tmp_path / "m.gif")]) == 2
    assert main(["animate", "slider_crank", "--simulate", "-o", str(tmp_path / "m.gif")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(line.startswith("mechdyn animate: error:") for line in err)
    assert "valid point names" in err[1] and "--t-end" in err[2]


def test_report_has_the_sections_and_the_stroke_is_twice_the_crank_radius(tmp_path, capsys):
    html = tmp_path / "report.html"
    rc = main(["report", "slider_crank", "--speed", "1500rpm", "--steps", "73", "-o", str(html)])
    assert rc == 0, capsys.readouterr().err
    text = html.read_text(encoding="utf-8")
    for section in ("<h2>Model</h2>", "<h3>Bodies</h3>", "<h3>Joints</h3>",
                    "<h3>Coordinates</h3>", "<h3>Drives</h3>", "<h2>Kinematics</h2>",
                    "<h3>Strokes and dead centres</h3>", "<h2>Kinetostatics</h2>",
                    "<h3>Driving torque</h3>", "<h3>Peak joint forces</h3>",
                    "<h2>Loads on the building</h2>", "<h3>Frame load extremes</h3>",
                    "<h3>Harmonics of the frame force and moment</h3>"):
        assert section in text, section
    # interactive: plotly.js once, in the page (offline), one figure per section
    assert text.count('class="plotly-graph-div"') == 4  # kinematics, kinetostatics, 2 loads
    assert text.count("Plotly.newPlot") == 4
    assert len(re.findall(r"<script[^>]*\bsrc=", text)) == 0  # nothing fetched
    assert _images(text) == ["gif"]  # the animation beside the kinematics plot
    # units in the headings, values rounded
    assert "<th>stroke (mm)</th>" in text and "<th>peak |F| (kN)</th>" in text
    assert "<th>peak |M| (N m)</th>" in text
    m = re.search(r"<td>cylinder</td>\s*<td>([0-9.]+)</td>", text)
    assert m, "stroke row of the slider 'cylinder'"
    assert float(m.group(1)) == round(2 * _crank_radius() * 1e3, 3)  # closed form: 2 r
    assert 4e6 < html.stat().st_size < 8e6  # plotly.js (~4.8 MB) once, the rest small


def test_report_without_animation_has_the_first_frame(tmp_path, capsys):
    html = tmp_path / "report.html"
    rc = main(["report", "four_bar", "--no-animation", "--steps", "37", "--trace", "coupler.P",
               "-o", str(html)])
    assert rc == 0, capsys.readouterr().err
    text = html.read_text(encoding="utf-8")
    assert _images(text) == ["png"]
    assert "coupler.P" in text  # the traced point is plotted


def test_report_of_a_simulation_has_energy_balance_and_events(tmp_path, capsys):
    html = tmp_path / "run.html"
    rc = main(["report", "slider_crank", "--simulate", "--t-end", "0.1s", "-o", str(html)])
    assert rc == 0, capsys.readouterr().err
    text = html.read_text(encoding="utf-8")
    for section in ("<h2>Simulation</h2>", "<h3>Run</h3>", "<h3>Energy balance</h3>",
                    "<h3>Events</h3>", "success", "<h2>Loads on the building</h2>",
                    "<h3>Spectrum</h3>", "<h3>Dominant components</h3>"):
        assert section in text, section
    assert text.count('class="plotly-graph-div"') == 3  # the run, frame loads, spectrum


def test_report_of_a_two_dof_press_holds_the_other_coordinate(tmp_path, capsys):
    html = tmp_path / "press.html"
    rc = main(["report", "clutchless_press", "--steps", "37", "--no-animation", "-o", str(html)])
    assert rc == 0, capsys.readouterr().err
    text = html.read_text(encoding="utf-8")
    assert "<h2>Kinetostatics</h2>" in text and "<h2>Loads on the building</h2>" in text
    assert re.search(r"held: <code>psi</code> at -?[0-9.]+ deg \(its initial value\)", text)
    assert re.search(r"<td[^>]*>psi</td>\s*<td[^>]*>held</td>", text)  # its holding torque
