"""Benchmark of the elastic mounting: the press cycle on its isolators against the rigid run.

Run ``python -m benchmarks foundation`` or ``python benchmarks/bench_foundation.py``.

The bundled press cycle (``mechdyn.examples.load("press_cycle")``, the isolators of its
``[foundation]`` table) is simulated over the same interval on its fixed frame and
``mechdyn.foundation.mounted`` on its isolators (three more coordinates, two massless
sleds, four isolator springs), one run each after a short warm-up run of each (kernels
compiled or loaded); the ratio of the wall times is the acceptance figure (at most 1.5).
The steps, evaluations and events of both runs are reported beside it: the mounted run
follows the base's vibration (13 to 33 Hz) and its impacts.
"""

from __future__ import annotations

import time
import warnings

import mechdyn
from mechdyn.foundation import FloorFrameWarning, mounted

T_END = 1.0  # two cycles: idle, engage, work stroke, release


def compare(t_end: float = T_END) -> dict:
    """Wall time (s) and trajectory of the rigid and the mounted press, one run each."""
    rigid = mechdyn.examples.load("press_cycle")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FloorFrameWarning)
        coupled = mounted(rigid)
    models = {"rigid": rigid.compile(), "mounted": coupled.compile()}
    for model in models.values():
        mechdyn.simulate(model, 1e-3, progress=False)  # kernels compiled / loaded
    out = {}
    for name, model in models.items():
        t0 = time.perf_counter()
        tr = mechdyn.simulate(model, t_end, progress=False)
        out[name] = (time.perf_counter() - t0, tr)
    return out


def run(quick: bool = False) -> list[dict]:
    """Rows for ``python -m benchmarks``: name, value, unit, note."""
    res = compare(0.5 if quick else T_END)
    rows = []
    for name, (wall, tr) in res.items():
        rows.append({"name": f"press_cycle {tr.t[-1]:g} s, {name}", "value": wall, "unit": "s",
                     "note": f"{tr.status}, {tr.stats['steps']} steps, "
                             f"{tr.stats['evaluations']} evaluations, {len(tr.events)} events"})
    rows.append({"name": "ratio mounted / rigid", "value": res["mounted"][0] / res["rigid"][0],
                 "unit": "", "note": "acceptance: at most 1.5"})
    return rows


def main() -> None:
    for row in run():
        print(f"{row['name']:<44} {row['value']:10.4g} {row['unit']:<4} {row.get('note', '')}")


if __name__ == "__main__":
    main()
