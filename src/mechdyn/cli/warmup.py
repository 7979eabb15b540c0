"""``mechdyn warmup``: compile the Numba kernels ahead of time and report the time."""

from __future__ import annotations

import time


def register(sub) -> None:
    """Add the ``warmup`` subcommand to ``sub`` (argparse subparsers)."""
    sub.add_parser(
        "warmup",
        help="compile the numba kernels now (once per machine) and report the time",
        description="Compile every Numba kernel now -- or load it from the cache, when an "
                    "earlier run compiled it -- so that the first analysis does not wait "
                    "for it; print where they are cached and how long each group took "
                    "(the dynamics, its compiled integration loop, the kinematic sweep, the "
                    "batched study). "
                    "Without it they are compiled on their first use.",
        epilog="The cache folder is NUMBA_CACHE_DIR when set, else the user's cache folder "
               "for mechdyn (e.g. ~/.cache/mechdyn).")


def run(args) -> int:
    """Compile the kernels (:func:`mechdyn.compiler.warmup`) and print the times."""
    from ..compiler import warmup
    from ..kernels import cache_dir

    t0 = time.perf_counter()
    times = warmup()
    if not times:
        print("numba is not installed: nothing to compile (the analyses run on NumPy; "
              "pip install mechdyn[fast] for the compiled kernels)")
        return 0
    print(f"kernels cached in {cache_dir()}")
    for name, seconds in times.items():
        if name != "total":
            print(f"  {name:<16} {seconds:6.2f} s")
    print(f"compiled (or loaded from the cache) in {time.perf_counter() - t0:.2f} s")
    return 0
