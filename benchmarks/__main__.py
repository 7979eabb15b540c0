"""Run every ``benchmarks/bench_*.py`` module and print one table.

Each module defines ``run(quick: bool = False) -> list[dict]``; a row has ``name``,
``value``, ``unit`` and optionally ``note``.  ``python -m benchmarks [NAME ...]``
runs the modules whose names contain one of the given words; ``--quick`` asks
for a shorter run.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
import time
from pathlib import Path


def _modules(filters: list[str]) -> list[str]:
    here = Path(__file__).parent
    names = sorted(m.name for m in pkgutil.iter_modules([str(here)])
                   if m.name.startswith("bench_"))
    if filters:
        names = [n for n in names if any(f in n for f in filters)]
    return names


def _fmt(value) -> str:
    if isinstance(value, float):
        if value != 0 and (abs(value) >= 1e6 or abs(value) < 1e-3):
            return f"{value:.3e}"
        return f"{value:,.4g}" if abs(value) < 1e4 else f"{value:,.0f}"
    return str(value)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    parser.add_argument("only", nargs="*", help="run only modules whose names contain these")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = parser.parse_args(argv)
    rows: list[tuple[str, dict]] = []
    failed = 0
    for name in _modules(args.only):
        mod = importlib.import_module(f"{__package__}.{name}")
        t0 = time.perf_counter()
        try:
            out = mod.run(quick=args.quick)
        except Exception as exc:  # noqa: BLE001 - report and go on with the others
            print(f"{name}: FAILED: {type(exc).__name__}: {exc}", file=sys.stderr)
            failed += 1
            continue
        print(f"{name}: done in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        rows.extend((name[len("bench_"):], r) for r in out)
    if rows:
        w_mod = max(len("module"), *(len(m) for m, _ in rows))
        w_name = max(len("benchmark"), *(len(r["name"]) for _, r in rows))
        vals = [_fmt(r["value"]) for _, r in rows]
        w_val = max(len("value"), *(len(v) for v in vals))
        w_unit = max(len("unit"), *(len(r.get("unit", "")) for _, r in rows))
        print(f"{'module':<{w_mod}}  {'benchmark':<{w_name}}  {'value':>{w_val}}  "
              f"{'unit':<{w_unit}}  note")
        print("-" * (w_mod + w_name + w_val + w_unit + 14))
        for (mod, r), v in zip(rows, vals, strict=True):
            print(f"{mod:<{w_mod}}  {r['name']:<{w_name}}  {v:>{w_val}}  "
                  f"{r.get('unit', ''):<{w_unit}}  {r.get('note', '')}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
