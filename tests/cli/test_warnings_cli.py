"""Warnings raised inside an analysis print as the command line's one-line form,
``mechdyn COMMAND: warning: ...``, not Python's ``file:line: Category: ...``."""

import sys
import warnings

from mechdyn.cli import main, warning_format


def _shown_on_stderr(message, category, filename, lineno, file=None, line=None):
    """Python's display of a warning (pytest records them instead)."""
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def test_friction_ignored_warning_of_reduce_is_one_cli_line(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = _shown_on_stderr
        rc = main(["reduce", "toggle_press_friction", "--steps", "37"])
    err = capsys.readouterr().err
    assert rc == 0
    lines = [ln for ln in err.splitlines() if "friction" in ln]
    assert len(lines) == 1
    assert lines[0].startswith("mechdyn reduce: warning: joint 'A' has friction = 0.08")
    assert "FrictionIgnoredWarning" not in err and ".py:" not in err


def test_the_format_is_python_s_again_after_the_command():
    before = warnings.formatwarning
    main(["examples"])
    assert warnings.formatwarning is before


def test_other_packages_warnings_keep_their_format():
    fmt = warning_format("simulate", fallback=lambda *a: f"{a[1].__name__}: {a[0]}\n")
    assert fmt(RuntimeWarning("overflow"), RuntimeWarning, "/elsewhere/numpy/core.py",
               3) == "RuntimeWarning: overflow\n"


def test_a_mechdyn_warning_class_is_in_the_cli_form_wherever_raised():
    from mechdyn.friction.ignored import FrictionIgnoredWarning

    fmt = warning_format("flywheel")
    assert fmt(FrictionIgnoredWarning("left\n  out"), FrictionIgnoredWarning,
               "/tmp/user_script.py", 7) == "mechdyn flywheel: warning: left out\n"
