"""The tutorial's code runs as written (its TOML block saved as slider_crank.toml)."""

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

TUTORIAL = Path(__file__).resolve().parents[2] / "docs" / "tutorial-slider-crank.md"


def test_tutorial_code_blocks_run(tmp_path, monkeypatch):
    text = TUTORIAL.read_text(encoding="utf-8")
    tomls = re.findall(r"```toml\n(.*?)```", text, re.S)
    (tmp_path / "slider_crank.toml").write_text(tomls[0], encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 5
    for k, block in enumerate(blocks):
        exec(compile(block, f"{TUTORIAL.name} block {k}", "exec"), namespace)
    assert namespace["sw"].status == "singular-position"
