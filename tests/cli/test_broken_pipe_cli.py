"""A reader that stops reading (``mechdyn ... | head``) ends the command silently."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import mechdyn

SRC = str(Path(mechdyn.__file__).resolve().parents[1])


@pytest.mark.timeout(120)
@pytest.mark.parametrize("argv", [["kinematics", "slider_crank"],
                                  ["simulate", "slider_crank", "--t-end", "0.01s"]])
def test_a_closed_pipe_ends_the_command_without_a_message(argv):
    """stdout is a pipe whose reader has gone before the first line: the command ends
    with 141 (as by SIGPIPE) and says nothing on stderr (no error, no traceback)."""
    read, write = os.pipe()
    os.close(read)  # every write to ``write`` now fails with EPIPE
    try:
        done = subprocess.run([sys.executable, "-m", "mechdyn", *argv], stdout=write,
                              stderr=subprocess.PIPE, text=True, timeout=110,
                              env={**os.environ, "PYTHONPATH": SRC})
    finally:
        os.close(write)
    err = "\n".join(line for line in done.stderr.splitlines()
                    if not line.startswith("mechdyn: ") and "compil" not in line)
    assert done.returncode == 141, done.stderr
    assert err.strip() == "", err
