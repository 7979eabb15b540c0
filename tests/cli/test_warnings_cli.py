"""Warnings raised inside an analysis print as the command line's one-line form,
``mechdyn COMMAND: warning: ...``, not Python's ``file:line: Category: ...``."""

import io
import warnings

from mechdyn.cli import main, warning_printer


def test_friction_ignored_warning_of_reduce_is_one_cli_line(capsys):
    rc = main(["reduce", "toggle_press_friction", "--steps", "37"])
    err = capsys.readouterr().err
    assert rc == 0
    lines = [ln for ln in err.splitlines() if "friction" in ln]
    assert len(lines) == 1
    assert lines[0].startswith("mechdyn reduce: warning: joint 'A' has friction = 0.08")
    assert "FrictionIgnoredWarning" not in err and ".py:" not in err


def test_other_packages_warnings_go_to_the_usual_display():
    seen = []
    show = warning_printer("simulate", fallback=lambda *a: seen.append(a[1]))
    out = io.StringIO()
    show(RuntimeWarning("overflow"), RuntimeWarning, "/elsewhere/numpy/core.py", 3, file=out)
    assert seen == [RuntimeWarning] and out.getvalue() == ""


def test_a_mechdyn_warning_class_is_shown_in_the_cli_form_wherever_raised():
    from mechdyn.dynamics.friction_ignored import FrictionIgnoredWarning

    out = io.StringIO()
    with warnings.catch_warnings():
        warnings.showwarning = warning_printer("flywheel")
        warnings.simplefilter("always")
        warnings.showwarning(FrictionIgnoredWarning("left out"), FrictionIgnoredWarning,
                             "/tmp/user_script.py", 7, file=out)
    assert out.getvalue() == "mechdyn flywheel: warning: left out\n"
