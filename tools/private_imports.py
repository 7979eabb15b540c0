"""Fail when a private name (``_x``) of one package of mechdyn is imported by another.

A seam between packages is a small public API (docs/architecture.md): a module may
import the private helpers of a sibling module in its own package, never those of
another package.  Run by ``make lint`` and ``make test``::

    python tools/private_imports.py [src/mechdyn]

Prints each offending import as ``module:line: imports _name from package.module`` and
exits 1 if there is any.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path


def _module_name(path: Path, root: Path) -> tuple[str, str]:
    """(dotted module name, dotted package name) of a source file."""
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
        return ".".join(parts), ".".join(parts)
    return ".".join(parts), ".".join(parts[:-1])


def _source(node: ast.ImportFrom, package: str) -> str:
    """The dotted module an ``from ... import`` reads from."""
    if not node.level:
        return node.module or ""
    base = package.split(".")
    if node.level > 1:
        base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def private_imports(root: Path) -> list[str]:
    """The private names imported across packages below ``root`` (a package folder)."""
    found = []
    for path in sorted(root.rglob("*.py")):
        module, package = _module_name(path, root)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom):
                continue
            src = _source(node, package)
            if not src.startswith(root.name):
                continue
            src_package = src if (root.parent / src.replace(".", "/")).is_dir() \
                else src.rpartition(".")[0]
            for alias in node.names:
                name = alias.name
                if name.startswith("_") and not name.startswith("__") and src_package != package:
                    found.append(f"{module}:{node.lineno}: imports {name} from {src}")
    return found


def main(argv: list[str]) -> int:
    root = Path(argv[1] if len(argv) > 1 else "src/mechdyn").resolve()
    found = private_imports(root)
    for line in found:
        print(line)
    if found:
        print(f"{len(found)} private name(s) imported across packages: make them part of "
              "the package's public API, or move the helper to where both use it")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
