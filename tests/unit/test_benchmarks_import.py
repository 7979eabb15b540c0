"""The benchmarks of ``make bench`` import (their timings are measured there, never here)."""

import importlib
import pkgutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
NAMES = sorted(m.name for m in pkgutil.iter_modules([str(ROOT / "benchmarks")])
               if m.name.startswith("bench_"))


@pytest.mark.parametrize("name", NAMES)
def test_benchmark_module_imports_and_its_helpers_resolve(name, monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT))
    module = importlib.import_module(f"benchmarks.{name}")
    assert callable(module.run)
    sys.modules.pop(f"benchmarks.{name}", None)
