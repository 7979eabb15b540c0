"""The check of `make lint` that no private name crosses a package (tools/)."""

import importlib.util
from pathlib import Path

import pytest

pytestmark = pytest.mark.timeout(60)
ROOT = Path(__file__).resolve().parents[2]


def _tool():
    spec = importlib.util.spec_from_file_location("private_imports",
                                                  ROOT / "tools" / "private_imports.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_a_private_name_across_packages_is_found_and_within_one_is_not(tmp_path):
    pkg = tmp_path / "mechdyn"
    for sub in ("a", "b"):
        (pkg / sub).mkdir(parents=True)
        (pkg / sub / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "a" / "one.py").write_text("def _helper():\n    return 1\n")
    (pkg / "a" / "two.py").write_text("from .one import _helper\n")          # same package
    (pkg / "b" / "three.py").write_text("from ..a.one import _helper\n")     # across
    (pkg / "b" / "four.py").write_text("from mechdyn.a.one import _helper, __all__\n")
    found = _tool().private_imports(pkg)
    assert found == ["mechdyn.b.four:1: imports _helper from mechdyn.a.one",
                     "mechdyn.b.three:1: imports _helper from mechdyn.a.one"]


def test_the_package_itself_imports_no_private_name_across_packages():
    assert _tool().private_imports(ROOT / "src" / "mechdyn") == []
