"""The README's first screen and its commands (issue 14 item 11: a README command that
failed as written, `mechdyn simulate press_cycle` without its required --t-end)."""

import re
import shlex
from pathlib import Path

import pytest

from mechdyn.cli import build_parser, main, negative_values

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
COMMANDS = re.findall(r"`(mechdyn [^`]*)`", README)


def test_the_first_screen_gives_the_two_set_up_commands():
    first = "\n".join(README.splitlines()[:20])
    targets = re.findall(r"^(\w[\w-]*):", (ROOT / "Makefile").read_text(), re.M)
    for command in ("make demo", "make test"):
        assert command in first
        assert command.split()[1] in targets
    assert ".venv/bin/mechdyn" in first  # where the command line lives


def _argv(command: str) -> list[str]:
    """A README command as argv: MODEL stands for a bundled example, `...` and an optional
    `[...]` are left out."""
    text = re.sub(r"\[[^\]]*\]|\.\.\.", "", command).replace("MODEL", "four_bar")
    return negative_values(shlex.split(text)[1:])


@pytest.mark.parametrize("command", COMMANDS)
def test_every_readme_command_parses(command):
    """Every command the README shows is accepted by the command line's parser as written
    (required options given, option names current)."""
    assert len(COMMANDS) >= 10
    args = build_parser().parse_args(_argv(command))
    assert callable(args.func)


def test_the_readme_press_cycle_command_runs_as_written(tmp_path, monkeypatch):
    command = next(c for c in COMMANDS if c.startswith("mechdyn simulate press_cycle"))
    monkeypatch.chdir(tmp_path)
    assert main(_argv(command) + ["--no-progress"]) == 0
    assert (tmp_path / "press.csv").stat().st_size > 1000


def _doc_commands():
    """The ``mechdyn ...`` command lines of the docs' shell blocks (fenced, not python, or
    indented by four spaces), continuation lines joined."""
    out = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        fence = None
        for line in page.read_text().replace("\\\n", " ").splitlines():
            if line.lstrip().startswith("```"):
                fence = None if fence is not None else line.strip()[3:] or "text"
                continue
            in_shell = (fence is not None and fence != "python") or line.startswith("    ")
            command = line.strip().split(" # ")[0].split("  #")[0]
            if in_shell and command.startswith("mechdyn "):
                out.append(pytest.param(command, id=f"{page.name}:{command[:40]}"))
    return out


@pytest.mark.parametrize("command", _doc_commands())
def test_every_docs_command_parses(command):
    args = build_parser().parse_args(_argv(command))
    assert callable(args.func)
