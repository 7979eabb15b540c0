"""The whole working cycle of the clutchless crank press (source paper, METHOD.md section 1).

Crank 1 (O-A), rod 2 (A-B), rocker 3 (C-B) pinned at C on the slider (ram) 4,
which slides along the x axis (the ram axis; "down" is -x, gravity (-9.81, 0)).
Link lengths, masses and inertias are the paper's published case
(l1 = 15 mm, l2 = 40 mm, l3 = 30 mm; m = 4.6, 20, 18, 100 kg;
J = 0.034, 0.036, 0.0441 kg m^2).  A pneumatic cylinder acts on the ram
through a separate piston 5, which touches the ram only by a unilateral
contact.

The cycle, as the paper describes it:

1. **idle** - preloaded springs hold the ram up against its upper stop
   (x_C = 28 mm); the crank turns and the rocker swings: the machine is a
   crank-rocker four-bar on the ram (2 DOF phi, psi; with the stop closed 1).
2. **engaging** - at a fixed crank angle (phi = 185 deg, every third
   revolution; see below) the control switches the cylinder on; it pushes the
   piston down, closes the 0.5 mm gap onto the ram (an impact) and pushes the
   ram 4 mm down, to the piston's lower stop (x_C = 24 mm).
3. **locking** - with the ram down, the rocker's swing now reaches the ram
   axis (psi = 0, before the crank's top dead centre); there it locks onto the
   ram (a plastic impact).  The machine is a 1-DOF slider-crank: the ram
   rises to top dead centre (25 mm), leaves the piston and does its 30 mm
   work stroke with a punch load in the last 3 mm.
4. **release** - the cylinder is switched off during the stroke (at
   phi = 487 deg, 127 deg into the revolution after the lock; the piston
   returns); when the ram comes back up through x_C = 23.5 mm the lock
   releases (no jump); the return torque of the second cylinder turns the
   rocker back and the springs return the ram to its upper stop (an impact
   with restitution 0.2, bounces, then it rests there): idle again.

The commands are fired by the crank angle, as a press control does with a cam
or an encoder on the crankshaft, not by a clock: the cylinder force is a table
over phi repeating every ``command_period`` (a periodic
:class:`~mechdyn.mechanism.load.Table`), and the lock and its release are
crossings of psi and of the ram position.  So every cycle starts at the same
crank phase however the crank speed varies (a time schedule drifts against the
crank: in its third cycle the rocker passes psi = 0 before the ram is down,
goes to the mirror branch and that cycle does not lock).  The machine locks and
releases once per command, indefinitely.

Values the paper does not give, chosen here (SI):

* **ram springs**: a preloaded spring pack pushing the ram up with 70 kN at
  the upper stop (stiffness 2e5 N/m), whose seat lands on the frame after
  6 mm of travel (the push then falls to zero over 2 mm), so that it holds
  the ram in idle but does not load the 30 mm work stroke.  The preload is
  set by the idle linkage: with the paper's masses at 43.5 rad/s the rocker
  and rod pull the ram down by up to 59 kN near the crank's top dead centre
  (computed with the ram held: ``x_stop_up`` = 28 mm); the paper gives no
  value.
* **upper stop** at x_C = 28 mm: 3 mm beyond the change-point distance
  l2 + l3 - l1 = 25 mm, so idle is a proper crank-rocker whose rocker never
  reaches the ram axis (it swings between -37 and -127 deg) - it can only
  lock after the ram is pushed below 25 mm; restitution 0.2 (steel on a
  damped stop).  Closer to 25 mm the idle linkage forces grow without bound
  (534 kN at 25.5 mm), which is why the paper's "1-2 mm" became 4 mm here.
* **piston**: 5 kg, stroke 4.5 mm (0.5 mm gap + 4 mm push, down to
  x_C = 24 mm), return spring 300 N; **cylinder force** 85 kN (beats the
  70.8 kN of the springs minus the ram's weight, with margin for the linkage
  forces that push the ram up).
* **cylinder command** by crank angle: on from phi = 185 deg to 487 deg
  (2 deg ramps; 302 deg, about 0.12 s) of every third revolution
  (``command_period`` 1080 deg, one work stroke per 3 revolutions, about
  0.42 s).  At 185 deg the ram is down (x_C = 24 mm) about 25 deg later, long
  before the rocker reaches the ram axis (psi = 0 at 342 deg); fired much
  later (e.g. 265 deg) the linkage pushes the ram back above 24.5 mm near
  330 deg and the lock is missed.  After the release (at 338 deg of the
  revolution after the lock) the springs need about 0.1 s (250 deg) to bring
  the ram back to its stop, so the next command at 185 deg can only come in
  the third revolution.
* **locking**: rocker-to-ram relative angle held (a CoordinateLock on joint
  C) when psi rises through 0 with the ram below 24 mm and the piston down.
* **return torque** of the second cylinder on the rocker: 20 N m towards
  negative psi while |psi| < 2 deg (inactive in idle, absorbed by the lock
  while locked, it picks the idle branch of the rocker at release).
* **flywheel**: 5 kg m^2 added to the crank (a press stores its stroke
  energy in a flywheel; the paper's crank alone, 0.034 kg m^2, would stall
  against the spring pack and the punch).
* **motor**: a linear torque-speed characteristic at the crank standing for
  the 4A80B4U3 induction motor through its reduction: 0 N m at the
  synchronous 46.2 rad/s, 34.5 N m at the nominal 43.5 rad/s (1.5 kW),
  limited to 76 N m (breakdown 2.2 x nominal).
* **punch load**: 15 kN against the ram in the last 3 mm of its stroke
  (x_C < -2 mm; bottom dead centre at -5 mm): about 45 J per stroke.

Use :func:`build` for the mechanism and :func:`run` to simulate it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..mechanism import Force, Mechanism, Spring, Table, Torque, TorqueSpeedCurve
from ..mechanism.contact import Contact, Stop
from ..mechanism.drive import Drive
from ..mechanism.switch import CoordinateLock, Switch, add_element
from ..modelfile.loader import build as build_doc
from ..modelfile.loader import read_document
from ..modelfile.switches import TABLES, parse_switches
from ..simulate_events import simulate_events

__all__ = ["build", "run", "PARAMETERS", "cylinder_command", "run_time", "load_model_file"]

#: every chosen value, SI (see the module docstring for the reasons)
PARAMETERS = dict(
    l1=0.015, l2=0.040, l3=0.030,
    m1=4.6, m2=20.0, m3=18.0, m4=100.0, m5=5.0,
    J1=0.034, J2=0.036, J3=0.0441, J_flywheel=5.0,
    x_stop_up=0.028, piston_gap=0.0005, piston_stroke=0.0045,
    k_ram=2e5, push_ram=70000.0, spring_travel=0.006, e_stop=0.2,
    k_piston=1e4, pull_piston=300.0, F_cylinder=85000.0,
    phi_on=np.deg2rad(185.0), phi_off=np.deg2rad(487.0), command_ramp=np.deg2rad(2.0),
    command_period=np.deg2rad(1080.0),
    M_return=20.0, psi_return=np.deg2rad(2.0),
    x_lock_below=0.0245, x_release=0.0235,
    F_punch=15000.0, x_punch=-0.002,
    omega_sync=46.2, omega_nominal=43.5, M_nominal=34.5, M_max=76.0,
    phi0=np.deg2rad(-64.1), omega0=43.5,
)


def cylinder_command(p: dict | None = None) -> Table:
    """The force of the engaging cylinder (N) as a periodic table over the crank angle.

    Parameters
    ----------
    p : dict, optional
        Parameters (default :data:`PARAMETERS`): ``F_cylinder`` from ``phi_on``
        to ``phi_off`` (rad), linear ramps of ``command_ramp`` before and after
        (rising to full force at ``phi_on``, falling from ``phi_off``), zero
        elsewhere, repeated every ``command_period`` of phi.

    Returns
    -------
    Table
        Over ``"phi"``, with ``period = command_period``.
    """
    p = PARAMETERS if p is None else p
    r = p["command_ramp"]
    on, off = p["phi_on"], p["phi_off"]
    return Table((on - r, on, off, off + r), (0.0, p["F_cylinder"], p["F_cylinder"], 0.0),
                 "phi", outside=0.0, period=p["command_period"])


def run_time(cycles: int = 4, p: dict | None = None) -> float:
    """A simulated time (s) that covers ``cycles`` whole cycles, the last one back in idle.

    The ram is back on its upper stop about 2.25 revolutions after the command
    of its cycle; the time is reckoned at the nominal motor speed (slower than
    the mean crank speed, so the estimate is on the late side).
    """
    p = PARAMETERS if p is None else p
    end = p["phi_on"] + (cycles - 1) * p["command_period"] + 2.25 * 2 * np.pi
    return float((end - p["phi0"]) / p["omega_nominal"])


def _rocker_angle(p, x_c, phi) -> float:
    """psi on the idle branch (B below the ram axis) for the crank at ``phi``."""
    a = p["l1"] * np.array([np.cos(phi), np.sin(phi)])
    c = np.array([x_c, 0.0])
    d = np.hypot(*(a - c))
    # B is at l2 from A and l3 from C: circle intersection, branch with B below
    l2, l3 = p["l2"], p["l3"]
    u = (c - a) / d
    along = (l2 ** 2 - l3 ** 2 + d ** 2) / (2 * d)
    h = np.sqrt(max(l2 ** 2 - along ** 2, 0.0))
    n = np.array([-u[1], u[0]])
    cands = [a + along * u + s * h * n for s in (1.0, -1.0)]
    b = min(cands, key=lambda v: v[1])
    return float(np.arctan2(b[1] - c[1], b[0] - c[0]))


def build(**overrides) -> Mechanism:
    """The press with its switches, stops, contact and loads.

    The cylinder command repeats every ``command_period`` of the crank angle,
    so the mechanism runs any number of cycles (the simulated time decides).

    Parameters
    ----------
    **overrides
        Replace entries of :data:`PARAMETERS`.

    Returns
    -------
    Mechanism
        With ``extras["initial"]`` set (idle, ram on its upper stop).
    """
    p = dict(PARAMETERS)
    p.update(overrides)
    l1, l2, l3 = p["l1"], p["l2"], p["l3"]
    xs = p["x_stop_up"]
    phi0 = p["phi0"]
    psi0 = _rocker_angle(p, xs, phi0)
    a0 = l1 * np.array([np.cos(phi0), np.sin(phi0)])
    b0 = np.array([xs, 0.0]) + l3 * np.array([np.cos(psi0), np.sin(psi0)])
    rod_angle = float(np.arctan2(*(b0 - a0)[::-1]))
    x_piston_up = xs + p["piston_gap"]
    y_ear = 0.06  # lateral position of the piston and the ram's ear, m

    m = Mechanism("clutchless press, whole cycle", gravity=(-9.81, 0.0),
                  description="Clutchless crank press: idle, engaging, locking, work stroke, "
                              "release (variable structure, stops, contact, lock).")
    m.add_ground(points={"O": (0.0, 0.0), "spring_base": (-0.2, 0.0),
                         "piston_top": (x_piston_up, y_ear),
                         "piston_anchor": (0.2, y_ear)})
    J1 = p["J1"] + p["J_flywheel"] - p["m1"] * (l1 / 2) ** 2  # about the centre of mass
    m.add_body("crank", mass=p["m1"], inertia=J1, com=(l1 / 2, 0.0),
               points={"A": (l1, 0.0)}, pose=(0.0, 0.0, phi0))
    m.add_body("rod", mass=p["m2"], inertia=p["J2"], com=(l2 / 2, 0.0),
               points={"B": (l2, 0.0)}, pose=(a0[0], a0[1], rod_angle))
    m.add_body("rocker", mass=p["m3"], inertia=p["J3"], com=(l3 / 2, 0.0),
               points={"B": (l3, 0.0)}, pose=(xs, 0.0, psi0))
    m.add_body("slider", mass=p["m4"], inertia=0.0, points={"ear": (0.0, y_ear)},
               pose=(xs, 0.0, 0.0))
    m.add_body("piston", mass=p["m5"], inertia=0.0, pose=(x_piston_up, y_ear, 0.0))
    m.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    m.add_revolute("A", "crank", "rod", "A", (0.0, 0.0))
    m.add_revolute("B", "rod", "rocker", "B", "B")
    m.add_revolute("C", "slider", "rocker", (0.0, 0.0), (0.0, 0.0))
    m.add_prismatic("guide", "ground", "slider", "O", (1.0, 0.0), (0.0, 0.0))
    m.add_prismatic("cylinder", "ground", "piston", "piston_top", (1.0, 0.0), (0.0, 0.0))
    m.add_coordinate("phi", kind="angle", body="crank")
    m.add_coordinate("psi", kind="angle", body="rocker")
    m.add_coordinate("p", kind="travel", joint="cylinder")

    # loads
    tr = p["spring_travel"]
    push = p["push_ram"]
    m.add(Force("ram_springs", "slider", (0.0, 0.0),
                Table((xs - tr - 0.002, xs - tr, xs), (0.0, push - p["k_ram"] * tr, push),
                      "slider.com.x"), direction=(1.0, 0.0)))
    L_pis = 0.2 - x_piston_up
    m.add(Spring("piston_return", "ground", "piston_anchor", "piston", (0.0, 0.0),
                 stiffness=p["k_piston"], free_length=L_pis - p["pull_piston"] / p["k_piston"]))
    m.add(Force("cylinder_force", "piston", (0.0, 0.0), cylinder_command(p),
                direction=(-1.0, 0.0)))
    ps = p["psi_return"]
    m.add(Torque("return_cylinder", "rocker",
                 Table((-2 * ps, -ps, ps, 2 * ps), (0.0, -p["M_return"], -p["M_return"], 0.0),
                       "psi"), reaction_body="slider"))
    xp = p["x_punch"]
    m.add(Force("punch", "slider", (0.0, 0.0),
                Table((xp - 1e-4, xp), (p["F_punch"], 0.0), "slider.com.x"),
                direction=(1.0, 0.0)))
    ws, wn, Mn, Mx = p["omega_sync"], p["omega_nominal"], p["M_nominal"], p["M_max"]
    slope = Mn / (ws - wn)
    w_max = ws - Mx / slope
    m.add(Drive("motor", "phi", TorqueSpeedCurve((0.0, w_max, ws, ws + 10.0),
                                                 (Mx, Mx, 0.0, -10.0 * slope))))

    # variable structure
    add_element(m, Stop("ram_stop", "joint:guide", upper=xs, restitution=p["e_stop"]))
    add_element(m, Stop("piston_stops", "p", lower=-p["piston_stroke"], upper=0.0))
    add_element(m, Contact("piston_on_ram", "piston", (0.0, 0.0), "slider", "ear",
                           (0.0, -1.0)))
    add_element(m, CoordinateLock("rocker_lock", "joint:C", frees=("psi",)))
    add_element(m, Switch("lock_on", "engage", "rocker_lock", variable="psi", value=0.0,
                          direction=+1,
                          guard=(("joint:guide", "<", p["x_lock_below"]),
                                 ("p", "<", -0.5 * p["piston_stroke"]))))
    add_element(m, Switch("lock_off", "release", "rocker_lock", variable="joint:guide",
                          value=p["x_release"], direction=+1,
                          guard=(("p", ">", -0.5 * p["piston_stroke"]),)))
    m.extras["initial"] = {"q": {"phi": phi0, "psi": psi0, "p": 0.0},
                           "qdot": {"phi": p["omega0"]}}
    return m


def run(cycles: int = 4, t_end: float | None = None, **options):
    """Simulate ``cycles`` work cycles; returns the Trajectory.

    Parameters
    ----------
    cycles : int
        Whole cycles to cover (idle, engage, lock, stroke, release, idle);
        sets the end time by :func:`run_time`.
    t_end : float, optional
        End time, s, instead.
    **options
        Go to :func:`mechdyn.simulate_events.simulate_events`, the segment loop of
        :func:`mechdyn.simulate` (here rtol 1e-9 and output every 0.5 ms unless given).

    Returns
    -------
    Trajectory
    """
    mech = build()
    if t_end is None:
        t_end = run_time(cycles)
    options.setdefault("rtol", 1e-9)
    options.setdefault("dt_out", 5e-4)
    return simulate_events(mech, t_end, **options)


def load_model_file(path=None):
    """The press from its model file ``press_cycle.toml`` (variable-structure tables
    read by :func:`mechdyn.modelfile.switches.parse_switches`).

    Works whether or not the model-file loader already knows the tables
    ``[[stops]]``, ``[[contacts]]``, ``[[coordinate_locks]]`` and ``[[switches]]``.
    """
    path = Path(path) if path is not None else Path(__file__).with_name("press_cycle.toml")
    doc = read_document(path.read_text(encoding="utf-8"), str(path))
    if any(t in doc for t in TABLES):
        rest = {k: v for k, v in doc.items() if k not in TABLES}
        try:
            mech = build_doc(doc, str(path))
        except ModelError:
            mech = build_doc(rest, str(path))
        if not any(mech.extras.get(k) for k in TABLES):
            probs = parse_switches(doc, mech, str(path))
            if probs:
                raise ModelError(probs)
        return mech
    return build_doc(doc, str(path))
