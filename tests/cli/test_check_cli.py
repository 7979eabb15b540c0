"""``mechdyn check``: every problem of a model at once, exit 0 / 2, JSON for tools."""

import json

from mechdyn import examples
from mechdyn.cli import main


def test_a_valid_model(capsys):
    assert main(["check", "press_cycle"]) == 0
    out = capsys.readouterr().out
    assert "valid" in out and "switchable elements" in out


def test_every_problem_at_once_as_json(tmp_path, capsys):
    text = examples.path("slider_crank").read_text(encoding="utf-8")
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('mass = "', 'mass = "-', 1).replace("revolute", "revolut", 1),
                   encoding="utf-8")
    assert main(["check", str(bad), "--json"]) == 2
    report = json.loads(capsys.readouterr().out)
    assert report["valid"] is False and len(report["problems"]) >= 2
    assert any("mass" in p for p in report["problems"])
    assert any("revolut" in p for p in report["problems"])
