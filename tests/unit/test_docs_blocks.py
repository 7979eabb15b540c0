"""Every Python block of docs/*.md runs as written (blocks of one page share their names;
the tutorial and the architecture page have tests of their own)."""

import re
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

DOCS = Path(__file__).resolve().parents[2] / "docs"
OWN_TESTS = ("tutorial-slider-crank.md", "architecture.md")
PAGES = [p for p in sorted(DOCS.glob("*.md")) if p.name not in OWN_TESTS
         and "```python" in p.read_text(encoding="utf-8")]


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_python_blocks_of_the_page_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # files the blocks write land here
    namespace: dict = {"__name__": "__docs__"}
    for k, block in enumerate(re.findall(r"```python\n(.*?)```",
                                         page.read_text(encoding="utf-8"), re.S)):
        exec(compile(block, f"{page.name} block {k}", "exec"), namespace)
