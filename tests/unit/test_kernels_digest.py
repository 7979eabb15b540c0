"""The kernels' cache digest covers every file whose code the kernels compile: their own
and the modules of mechdyn.integrate they import (the DOP853 tableau, step control and
dense output, written there once for the Python stepper and the compiled loop)."""

import ast
from pathlib import Path

import mechdyn.kernels as kernels

KERNELS = Path(kernels.__file__).parent


def _integrate_imports(path: Path) -> set[str]:
    """The modules of mechdyn.integrate a kernels file imports, as file names."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if not isinstance(node, ast.ImportFrom):
            continue
        module = node.module or ""
        if node.level == 2 and module.startswith("integrate."):
            found.add(module.split(".")[1] + ".py")
        elif node.level == 2 and module == "integrate":
            found.update(alias.name + ".py" for alias in node.names)
        elif module.startswith("mechdyn.integrate"):
            parts = module.split(".")
            found.update([parts[2] + ".py"] if len(parts) > 2
                         else [alias.name + ".py" for alias in node.names])
    return found


def test_every_integrate_module_the_kernels_import_is_digested():
    imported = set().union(*(_integrate_imports(f) for f in KERNELS.glob("*.py")))
    assert {"dop853_tableau.py", "dop853_control.py", "dop853_dense.py"} <= imported
    assert imported <= set(kernels.COMPILED_INTEGRATE)
    digested = kernels.digested_sources()
    for name in kernels.COMPILED_INTEGRATE:
        assert KERNELS.parent / "integrate" / name in digested
        assert (KERNELS.parent / "integrate" / name).is_file()


def test_the_digest_changes_with_a_compiled_integrate_module(monkeypatch):
    before = kernels.sources_digest()
    target = KERNELS.parent / "integrate" / "dop853_control.py"
    real = Path.read_bytes

    def edited(self):
        data = real(self)
        return data + b"\n# edited\n" if self == target else data

    monkeypatch.setattr(Path, "read_bytes", edited)
    assert kernels.sources_digest() != before
