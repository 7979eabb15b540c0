"""A cyclic-automaton example: a bolt driven against a buffer and a stop.

A bolt (1.2 kg) slides in its guide; a preloaded driving spring pushes it
forward.  On its way it meets a buffer (0.4 kg, held back by a stiff buffer
spring against its own rear stop) through a unilateral contact: the contact
closes with an impact (restitution 0.5), the bolt and buffer move together
against the buffer spring, separate when the buffer spring throws the bolt
back, and touch again - all found by the event loop.  The buffer's travel
ends on a front stop (plastic).  Use :func:`build` and :func:`run`.
"""

from __future__ import annotations

from ..mechanism import Mechanism, Spring
from ..mechanism.contact import Contact, Stop
from ..mechanism.switch import add_element
from ..simulate_events import simulate_events

__all__ = ["build", "run"]


def build() -> Mechanism:
    """The bolt-buffer mechanism (gravity off: a horizontal automaton)."""
    m = Mechanism("bolt and buffer", gravity=(0.0, 0.0),
                  description="Bolt driven against a buffer: unilateral contact, stops.")
    m.add_ground(points={"rear": (-0.5, 0.0), "buffer_seat": (0.3, 0.02)})
    m.add_body("bolt", mass=1.2, inertia=0.002, points={"face": (0.05, 0.0)})
    m.add_body("buffer", mass=0.4, inertia=0.0005, pose=(0.10, 0.0, 0.0))
    m.add_prismatic("bolt_guide", "ground", "bolt", (0.0, 0.0), (1.0, 0.0))
    m.add_prismatic("buffer_guide", "ground", "buffer", (0.10, 0.0), (1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="bolt_guide")
    m.add_coordinate("u", kind="travel", joint="buffer_guide")
    # driving spring: pushes the bolt forward with about 60 N over its travel
    m.add(Spring("drive", "ground", "rear", "bolt", (0.0, 0.0), stiffness=200.0,
                 free_length=0.8))
    # buffer spring: holds the buffer back against its rear stop with 40 N
    m.add(Spring("buffer_spring", "ground", "buffer_seat", "buffer", (0.0, 0.02),
                 stiffness=2.0e4, free_length=0.2 + 40.0 / 2.0e4))
    add_element(m, Stop("buffer_stops", "u", lower=0.0, upper=0.01))
    add_element(m, Stop("bolt_rear", "s", lower=-0.02))
    add_element(m, Contact("face_on_buffer", "bolt", "face", "buffer", (0.0, 0.0),
                           (0.0, 1.0), restitution=0.5))
    m.extras["initial"] = {"q": {"s": -0.02, "u": 0.0}, "qdot": {"s": 0.0, "u": 0.0}}
    return m


def run(t_end: float = 0.2, **options):
    """Simulate the bolt-buffer cycle; returns the Trajectory."""
    options.setdefault("dt_out", 2e-4)
    return simulate_events(build(), t_end, **options)
