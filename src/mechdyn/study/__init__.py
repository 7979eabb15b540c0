"""Design studies: many variants of one model file, analysed, tabulated and optimised.

Parameters are model-file paths (:mod:`.parameters`), varied over a design
(:mod:`.designs`); each variant is analysed (:mod:`.analyses`) in batches
(:mod:`.evaluate`) in this process, local worker processes or on a Dask cluster
(:mod:`.execute`), and written as one table row as the batches finish
(:mod:`.output`); :mod:`.optimise` minimises a figure, :mod:`.plots` draws the table.
The guide is ``docs/studies.md``.

>>> from mechdyn.study import BaseModel, design, parse_range
>>> base = BaseModel("slider_crank")
>>> design([parse_range(base, "bodies.rod.mass=1kg..2kg")], 2, "grid").shape
(2, 1)
"""

from .analyses import (
    Combined,
    FlywheelSize,
    KinematicSummary,
    KinetostaticExtremes,
    Outcome,
    SimulationMetrics,
)
from .designs import Range, design, parse_range
from .execute import run_study
from .optimise import Constraint, Optimum, optimise, parse_constraint
from .output import read_table, write_table
from .parameters import BaseModel, Parameter
from .plots import pareto_front, plot_pareto, plot_scatter

__all__ = ["BaseModel", "Parameter", "Range", "parse_range", "design", "run_study",
           "KinetostaticExtremes", "KinematicSummary", "FlywheelSize", "SimulationMetrics",
           "Combined", "Outcome", "optimise", "Constraint", "Optimum", "parse_constraint",
           "read_table", "write_table", "pareto_front", "plot_scatter", "plot_pareto"]
