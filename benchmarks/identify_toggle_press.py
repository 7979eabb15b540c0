"""Identify the toggle press of Wang & Wei (2019) from its published figures.

The paper (J. Vibration and Shock 2019 no. 11) gives the idle driving torque's extremes and
turning points and the jump under its pulse load, but not the link dimensions, masses,
speed or the zero of its crank angle q1.  This script searches them within stated plausible
bounds (``BOUNDS``, ``MASS_BOUNDS``) so that a kinetostatic sweep reproduces the published
figures (``PAPER``), and prints each figure's residual.

    PYTHONPATH=src python benchmarks/identify_toggle_press.py [--seconds 240] [--seed 3]
        [--write src/mechdyn/examples/toggle_press_paper.toml]

The search model is a closed-form one written here, independent of mechdyn's solver: the
loop-closure positions of the six-bar sampled over a turn, their derivatives with respect
to the crank angle by FFT (the positions are periodic), the driving torque by the power
balance at constant speed and the pin forces at q1 = 139 deg by Newton-Euler, body by body.

Each moving link's mass is a set of lumps at body-fixed points (rocker CD: at D and at two
points off its line; toggle BDE: at B, D, E; link EF: at E, F and two points off its line)
plus a centroidal inertia of its own, so the centre of mass may lie anywhere in the hull
of those points.  The torque is linear in the lumps, so for each geometry they come from
bounded linear least squares on the paper's torque values and turning angles (the
turning points are the torque's extremes: the paper says where it increases and where it
decreases).  Differential evolution searches the geometry, the speed and the offset of q1;
one process, a time budget.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.optimize import differential_evolution

# the search model, beside this script (run as `python benchmarks/identify_toggle_press.py`)
from toggle_press_model import (
    BOUNDS,
    COLUMNS,
    F_R,
    FRAME,
    HIGH,
    LOW,
    MASS_BOUNDS,
    PAPER,
    PULSE,
    SCALE,
    STEP,
    W_OFF,
    evaluate,
    positions,
    shift,
)


def search(seconds: float, seed: int, level=True, popsize=15, x0=None):
    """Differential evolution over BOUNDS within a time budget (s); the best vector."""
    t0 = time.time()
    res = differential_evolution(lambda z: math.log1p(evaluate(z, level)[0]),
                                 list(zip(LOW, HIGH, strict=True)), maxiter=100000,
                                 popsize=popsize, seed=seed, tol=0.0, polish=False,
                                 init="sobol", mutation=(0.5, 1.0), recombination=0.9, x0=x0,
                                 callback=lambda *a, **k: time.time() - t0 > seconds)
    return res.x, time.time() - t0


# starts: the geometry and speed of the earlier identification (idle curve only, centres
# of mass on the link lines, q1 = absolute angle), and the result of the first stage
# (--start previous --pin-scale 1000 --seed 21 --seconds 180, before the inertia floor)
STARTS = {
    "previous": [0.05451, -0.26470, 0.07754, 0.18511, 0.15762, 0.13474, math.radians(-170.76),
                 0.41136, -0.26238, 1.0, 88.06, 0.0],
    "shape": [0.068685, -0.269214, 0.155629, 0.288479, 0.120057, 0.103506, -1.033028,
              0.447727, -0.041359, 0.472377, 93.398289, -178.981647],
}


def polish(z, level=True, iters=1500):
    """Nelder-Mead on the continuous geometry and speed (branch and q1's zero kept)."""
    from scipy.optimize import minimize

    free = [i for i in range(len(BOUNDS)) if BOUNDS[i][0] not in ("branch", "q1_zero")]
    z = np.array(z, dtype=float)

    def fun(y):
        v = z.copy()
        v[free] = np.clip(y, LOW[free], HIGH[free])
        return evaluate(v, level)[0]

    res = minimize(fun, z[free], method="Nelder-Mead",
                   options={"maxiter": iters, "xatol": 1e-8, "fatol": 1e-8, "adaptive": True})
    if res.fun < evaluate(z, level)[0]:
        z[free] = np.clip(res.x, LOW[free], HIGH[free])
    return z


def _rounded(p):
    """The geometry as written in the model file (0.001 mm, 0.001 deg, 0.01 rpm, 0.5 deg)."""
    p = np.array(p, dtype=float)
    p[[0, 1, 2, 3, 4, 5, 7, 8]] = np.round(p[[0, 1, 2, 3, 4, 5, 7, 8]], 6)
    p[6] = math.radians(round(math.degrees(p[6]), 3))
    p[9] = 1.0 if p[9] >= 0 else -1.0
    p[10] = round(p[10], 2)
    p[11] = shift(p) * STEP
    return p


def local_points(p):
    """Each body's lump points (and its joint points) in its own frame (m)."""
    lbd, lcd, lde, gam, lef = p[3], p[4], p[5], p[6], p[7]
    return {"rocker": {"D": (lcd, 0.0), "M+": (lcd / 2, W_OFF * lcd),
                       "M-": (lcd / 2, -W_OFF * lcd)},
            "toggle": {"B": (lbd, 0.0), "D": (0.0, 0.0),
                       "E": (lde * math.cos(gam), lde * math.sin(gam))},
            "link": {"E": (0.0, 0.0), "F": (lef, 0.0), "M+": (lef / 2, W_OFF * lef),
                     "M-": (lef / 2, -W_OFF * lef)},
            "slider": {"F": (0.0, 0.0)}}


def inertial(p, x):
    """Per body: mass (kg), centre of mass in its frame (m), centroidal inertia (kg m^2)."""
    pts = local_points(p)
    out = {}
    for body in pts:
        lumps = [(xi, np.array(pts[body][nm])) for xi, (b, nm) in zip(x, COLUMNS, strict=True)
                 if b == body and nm != "J"]
        m = sum(xi for xi, _ in lumps)
        c = sum(xi * r for xi, r in lumps) / m
        J = sum(xi * float(np.sum((r - c) ** 2)) for xi, r in lumps)
        if (body, "J") in COLUMNS:
            J += x[COLUMNS.index((body, "J"))]
        out[body] = (m, c, J)
    return out


def _body(name, description, mass, inertia, com, pose, points) -> str:
    """One ``[bodies.NAME]`` table (and its points) of the model file."""
    out = [f"[bodies.{name}]", f'description = "{description}"', f'mass = "{mass:.4f} kg"',
           f'inertia = "{inertia:.6f} kg*m^2"', f"com = {com}", f"pose = {pose}"]
    if points:
        out.append(f"[bodies.{name}.points]")
        out += [f"{k} = {v}" for k, v in points.items()]
    return "\n".join(out) + "\n\n"


def model_toml(p, x, F_r, header: str = "") -> str:
    """The model file (TOML text) of geometry ``p``, lumps ``x`` and load F_r (N); the
    coordinate phi is the paper's q1 (an offset of -q1_zero); sketch at q1 = 90 deg."""
    P, _ = positions(p, np.array([math.radians(90.0 + p[11])]))
    pt = {k: v[0] for k, v in P.items()}
    r, cx, cy, lbd, lcd, lde, gam, lef, xs = p[:9]
    n_rpm, zero = p[10], p[11]
    mm = lambda v: f'"{1e3 * v:.4f} mm"'  # noqa: E731
    vec = lambda v: f"[{mm(v[0])}, {mm(v[1])}]"  # noqa: E731
    th = lambda a, b: math.degrees(math.atan2(*(pt[b] - pt[a])[::-1]))  # noqa: E731
    pose = lambda o, a: f'[{mm(o[0])}, {mm(o[1])}, "{a:.6f} deg"]'  # noqa: E731
    inert = inertial(p, x)
    loc = local_points(p)
    rows = [("crank", "crank AB, balanced (centre of mass at A); frame origin A", 10.0, 0.05,
             (0.0, 0.0), pose(pt["A"], th("A", "B")), {"B": vec((r, 0.0))})]
    for name, desc, origin, pts in (
            ("toggle", "triangular toggle BDE; frame origin D, x axis towards B", "D", "BDE"),
            ("rocker", "link CD; frame origin C, x axis towards D", "C", "D"),
            ("link", "link EF; frame origin E, x axis towards F", "E", "F"),
            ("slider", "slide with the punch; frame origin F", "F", "")):
        m, c, J = inert[name]
        angle = th(*FRAME[name]) if name in FRAME else 0.0
        rows.append((name, desc, m, J, c, pose(pt[origin], angle),
                     {k: vec(loc[name][k]) for k in pts}))
    bodies = "".join(_body(*row[:4], vec(row[4]), *row[5:]) for row in rows)
    joints = "".join(
        f'[joints.{j}]\ntype = "revolute"\nparent = "{par}"\nchild = "{ch}"\n{where}\n\n'
        for j, par, ch, where in (
            ("A", "ground", "crank", 'parent_point = "A"'), ("B", "crank", "toggle", 'point = "B"'),
            ("C", "ground", "rocker", 'parent_point = "C"'),
            ("D", "rocker", "toggle", 'point = "D"'), ("E", "toggle", "link", 'parent_point = "E"'),
            ("F", "link", "slider", 'parent_point = "F"')))
    return f"""{header}
[model]
name = "triangular toggle press (paper, identified)"
description = "Toggle press of Wang and Wei 2019 with dimensions identified from its figures."
gravity = ["0 m/s^2", "-9.81 m/s^2"]

[ground.points]
A = {vec((0.0, 0.0))}
C = {vec((cx, cy))}
S = {vec((xs, 0.0))}

{bodies}
{joints}
[joints.slide]
type = "prismatic"
parent = "ground"
child = "slider"
parent_point = "S"
axis = "90 deg"

[coordinates.phi]
kind = "angle"
body = "crank"
offset = "{-zero:.1f} deg"
description = "the paper's crank angle q1: the crank's absolute angle minus {zero:.1f} deg"

[initial]
phi = "90 deg"

[initial_speed]
phi = "{n_rpm:.2f} rpm"

[[loads]]
type = "force"
name = "working_load"
body = "slider"
magnitude = {{ pulse = "{F_r:.1f} N", start = "{PULSE[0]} deg", duration = "{PULSE[1]} deg", \
variable = "phi", period = "360 deg" }}
direction = [0, -1]
"""


def _residual(key, v, target) -> str:
    if key.endswith("_deg"):
        return f"{(v - target + 180) % 360 - 180:+.2f} deg"
    return f"{100 * (v - target) / abs(target):+.2f} %"


def header(p, x, f) -> str:
    """Comment block of the model file: source, identification, bounds and residuals."""
    lines = [
        "# toggle_press_paper.toml -- the triangular-toggle six-bar press of Wang Zhongshuang",
        "# and Wei Jing, J. Vibration and Shock 2019 no. 11 (docs/references.md [3]), with",
        "# dimensions, masses, speed, pulse force and the zero of the crank angle IDENTIFIED",
        "# from the paper's figures (the paper gives none of them).  The invented press is",
        "# toggle_press.toml.",
        "#",
        "# Topology and loads as the paper: crank AB (balanced: the paper's known loads have no",
        "# crank weight), triangular toggle BDE, link CD on the frame at C, link EF, slide F",
        "# (vertical); gravity on CD, BDE, EF and the slide; the working load F_r downwards,",
        f"# with gravity, a pulse over q1 = {PULSE[0]} ... {PULSE[0] + PULSE[1]} deg "
        "(about 139 deg, before bottom",
        "# dead centre).  The coordinate phi is the paper's q1 (its offset below).",
        "#",
        "# Identification: benchmarks/identify_toggle_press.py (scipy differential evolution over",
        "# the geometry, speed and q1's zero; each link's mass as lumps at its joints and off its",
        "# line plus an own inertia, by bounded linear least squares; Nelder-Mead polish);",
        "# objective = sum of squared residuals of the paper's figures in units of 1 % (torques),",
        "# 2 deg (angles), 10 % (pin forces under the pulse) and 20 % (idle pin forces), and a",
        "# steep penalty on a torque or angle beyond 90 % of its aim (1 %, 2 deg), from a",
        "# closed-form kinetostatic sweep written there; checked with mechdyn.kinetostatics.",
        "# Bounds (A at the origin; the search box):",
    ]
    for name, lo, hi, unit in BOUNDS:
        if unit == "m":
            lines.append(f"#   {name:10s} {1e3 * lo:8.1f} ... {1e3 * hi:8.1f} mm")
        elif unit == "rad":
            lines.append(f"#   {name:10s} {math.degrees(lo):8.1f} ... {math.degrees(hi):8.1f} deg")
        elif name != "branch":
            lines.append(f"#   {name:10s} {lo:8.1f} ... {hi:8.1f} {unit}")
    lines += [f"#   mass of {b:6s}  {lo:8.1f} ... {hi:8.1f} kg"
              for b, (lo, hi) in MASS_BOUNDS.items()]
    lines += [f"#   F_r        {F_R[0]:8.1f} ... {F_R[1]:8.1f} N",
              "#   centres of mass: in the hull of the lumps (toggle: triangle BDE; CD and EF:",
              f"#   between the joints and up to {W_OFF:.0%} of the length off the line at "
              "mid-length);",
              "#   own centroidal inertia from half a uniform link's (plate's) of its mass to",
              "#   (mass bound) L^2 / 12 (toggle: (a^2 + b^2 + c^2) / 36); four-bar transmission",
              "#   angle 30 ... 150 deg over the turn; EF within 45 deg of the slide; at",
              "#   q1 = 139 deg the punch moves down and is at most 3 mm above bottom dead centre.",
              "# Identified values (rounded as written below):"]
    for (name, _, _, unit), v in zip(BOUNDS, p, strict=True):
        if unit == "m":
            lines.append(f"#   {name:10s} {1e3 * v:10.3f} mm")
        elif unit == "rad":
            lines.append(f"#   {name:10s} {math.degrees(v):10.3f} deg")
        else:
            lines.append(f"#   {name:10s} {v:9.3f} {unit}")
    for body, (m, c, J) in inertial(p, x).items():
        lines.append(f"#   {body:7s} {m:7.3f} kg, centre ({1e3 * c[0]:.1f}, {1e3 * c[1]:.1f}) mm"
                     f" in its frame, J_c {J:.5f} kg m^2")
    lines += [f"#   F_r        {f['F_r_N']:9.1f} N (the paper's torque fall / the slide's rate)",
              f"# Kinematics: stroke {f['stroke_mm']:.1f} mm, bottom dead centre at q1 = "
              f"{f['BDC_deg']:.1f} deg; at 139 deg", f"#   the punch is "
              f"{f['above_BDC_139_mm']:.3f} mm above it (the paper says 3 mm) and moves at "
              f"{f['slide_rate_139_mm_per_rad']:.3f} mm/rad.",
              "# Figures (0.5 deg sweep): paper | this model | residual"]
    for key, target in PAPER.items():
        lines.append(f"#   {key:16s} {target:11.4f} | {f[key]:11.4f} | "
                     f"{_residual(key, f[key], target)}")
    lines.append(f"#   turning points (deg of q1): {f['turning_deg']} (paper: 1, 60, 284, 341)")
    lines += ["# (the idle values at 139 deg are the paper's pulse values divided by its stated",
              "# rises: 9.2786 / (1 - 0.455442), 1045.7381 / 4.527272, ...)",
              "#", "# Sketch: q1 = 90 deg."]
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=240.0, help="time budget of the search")
    ap.add_argument("--no-level", action="store_true",
                    help="fit the masses without the idle torque level at 139 deg")
    ap.add_argument("--start", choices=sorted(STARTS), default=None,
                    help="start the search from one of STARTS")
    ap.add_argument("--x0", default=None, help="start from this saved .npy vector")
    ap.add_argument("--three-mm", action="store_true",
                    help="fit the punch 3 mm above bottom dead centre at 139 deg (10 %%)")
    ap.add_argument("--pin-scale", type=float, default=1.0,
                    help="multiply the pin forces' residual scales (large: ignore them)")
    ap.add_argument("--params", default=None, help="skip the search: a saved .npy vector")
    ap.add_argument("--write", default=None, help="write the identified model file here")
    args = ap.parse_args(argv)
    level = not args.no_level
    SCALE.update({k: v * args.pin_scale for k, v in SCALE.items() if k.startswith("F_")})
    if args.three_mm:
        PAPER["above_BDC_139_mm"], SCALE["above_BDC_139_mm"] = 3.0, 0.3
    if args.params:
        best = np.load(args.params)
    else:
        x0 = np.load(args.x0) if args.x0 else (STARTS[args.start] if args.start else None)
        best, sec = search(args.seconds, args.seed, level, x0=x0)
        best = polish(best, level)
        print(f"cost {evaluate(best, level)[0]:.4g} after {sec:.0f} s of search")
        np.save(f"/tmp/toggle_press_paper_params_{args.seed}.npy", best)
    best = _rounded(best)
    cost, x, f = evaluate(best, level)
    print(f"cost of the rounded values {cost:.4g}")
    for (name, _, _, unit), v in zip(BOUNDS, best, strict=True):
        print(f"  {name:10s} {v: .6g} {unit}")
    for body, (m, c, J) in inertial(best, x).items():
        print(f"  {body:8s} {m:.4f} kg, centre {np.round(1e3 * c, 2)} mm, J_c {J:.6f} kg m^2")
    for k, v in f.items():
        tgt = PAPER.get(k)
        print(f"  {k:28s} {v}" + (f"   paper {tgt:.4f}  {_residual(k, v, tgt)}"
                                   if tgt is not None else ""))
    if args.write:
        with open(args.write, "w", encoding="utf-8") as fh:
            fh.write(model_toml(best, x, round(f["F_r_N"], 1), header(best, x, f)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
