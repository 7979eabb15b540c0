"""Fast start: ``import mechdyn`` and ``mechdyn --help`` load none of the heavy libraries,
the public names still resolve, and the compiled kernels go to the user's cache folder."""

import argparse
import importlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

import mechdyn
from mechdyn import cli

SRC = str(Path(mechdyn.__file__).resolve().parents[1])
HEAVY = ("scipy", "pandas", "matplotlib", "numba", "pint")


def _python(code: str, **env) -> str:
    environ = {**os.environ, "PYTHONPATH": SRC, **env}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=environ, check=True, timeout=120)
    return done.stdout.strip()


def _heavy_after(statement: str) -> str:
    return _python(f"{statement}; import sys; print(sorted(m for m in sys.modules "
                   f"if m.split('.')[0] in {HEAVY!r}))")


def test_import_mechdyn_loads_no_heavy_library():
    assert _heavy_after("import mechdyn") == "[]"


def test_help_loads_no_heavy_library_and_no_subcommand_module():
    out = _python("import sys, contextlib, io\n"
                  "from mechdyn.cli import main\n"
                  "with contextlib.redirect_stdout(io.StringIO()):\n"
                  "    try:\n"
                  "        main(['--help'])\n"
                  "    except SystemExit:\n"
                  "        pass\n"
                  f"print(sorted(m for m in sys.modules if m.split('.')[0] in {HEAVY!r}\n"
                  "       or m.startswith('mechdyn.cli.')))")
    assert out == "[]"


@pytest.mark.parametrize("name", mechdyn.__all__)
def test_every_public_name_resolves(name):
    value = getattr(mechdyn, name)
    assert value is not None
    namespace: dict = {}
    exec(f"from mechdyn import {name}", namespace)
    assert namespace[name] is value


def test_all_and_dir_are_complete_and_unknown_names_fail():
    assert len(set(mechdyn.__all__)) == len(mechdyn.__all__)
    assert set(mechdyn.__all__) <= set(dir(mechdyn))
    assert "__version__" in dir(mechdyn)
    with pytest.raises(AttributeError, match="no attribute 'Mechansim'"):
        mechdyn.Mechansim  # noqa: B018
    assert mechdyn.units is importlib.import_module("mechdyn.units")


def test_a_submodule_imported_first_does_not_hide_the_public_name():
    # the package mechdyn.simulate imported first: mechdyn.simulate is still the function
    assert _python("import mechdyn.simulate, mechdyn; print(mechdyn.simulate.__module__)") \
        == "mechdyn.simulate.run"
    assert mechdyn.simulate is sys.modules["mechdyn.simulate"].simulate
    assert mechdyn.examples is sys.modules["mechdyn.examples"]


def test_help_lists_every_subcommand_with_its_help_line(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["--help"])
    assert exc.value.code == 0
    out = " ".join(capsys.readouterr().out.split())
    for name, line in cli.SUBCOMMANDS.items():
        assert f"{name} {line}" in out


@pytest.mark.parametrize("name", list(cli.SUBCOMMANDS))
def test_the_help_table_is_what_each_module_registers(name):
    sub = argparse.ArgumentParser().add_subparsers()
    importlib.import_module(f"mechdyn.cli.{name}").register(sub)
    action = next(a for a in sub._choices_actions if a.dest == name)
    assert action.help == cli.SUBCOMMANDS[name]


def test_a_subcommand_help_is_its_own(capsys):
    with pytest.raises(SystemExit):
        cli.main(["warmup", "--help"])
    assert "usage: mechdyn warmup" in capsys.readouterr().out


def test_a_misspelled_subcommand_is_a_clear_error(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["simulat", "x.toml"])
    assert exc.value.code == 2
    assert "invalid choice: 'simulat'" in capsys.readouterr().err


def test_the_kernel_cache_is_the_users_cache_folder_unless_set(tmp_path):
    from platformdirs import user_cache_dir

    code = ("import mechdyn.kernels as k, os; print(k.cache_dir()); "
            "print(os.environ['NUMBA_CACHE_DIR'])")
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**env, "PYTHONPATH": SRC}, check=True, timeout=120)
    kernels = importlib.import_module("mechdyn.kernels")
    expected = os.path.join(user_cache_dir("mechdyn", appauthor=False),
                            f"kernels-{kernels.sources_digest()}")
    assert done.stdout.split() == [expected, expected]
    assert _python(code, NUMBA_CACHE_DIR=str(tmp_path)).split() == [str(tmp_path)] * 2


def test_numba_imported_first_still_caches_in_the_users_folder():
    pytest.importorskip("numba")
    out = _python("import numba, os; os.environ.pop('NUMBA_CACHE_DIR', None); "
                  "import numba.core.config as c; c.CACHE_DIR = ''; "
                  "import mechdyn.kernels.rows_numba as r; "
                  "print(r.body_pose._cache._cache_path)")
    from platformdirs import user_cache_dir

    # the user's folder (not cache_dir() of this process: NUMBA_CACHE_DIR may be set here)
    kernels = importlib.import_module("mechdyn.kernels")
    assert out.startswith(os.path.join(user_cache_dir("mechdyn", appauthor=False),
                                       f"kernels-{kernels.sources_digest()}"))


def test_mechdyn_warmup_runs(capsys):
    assert cli.main(["warmup"]) == 0
    out = capsys.readouterr().out
    if "not installed" not in out:
        assert all(g in out for g in ("dynamics", "integration loop", "kinematic sweep",
                                      "batched study"))
        assert importlib.import_module("mechdyn.kernels").cache_dir() in out
        assert "compiled (or loaded from the cache) in" in out
