"""Kinematic analysis in absolute coordinates with exact Jacobians."""

from ..model.constraints import (
                      coordinates,
                      jacobian,
                      point_acceleration,
                      point_position,
                      point_velocity,
                      residual,
)
from .analogs import (
                      acceleration_bias,
                      accelerations,
                      finite_difference_analogs,
                      velocities,
                      velocity_analogs,
)
from .assembly import assemble, branch_sign, joint_residuals, singularity, solve_position

__all__ = ["accelerations", "acceleration_bias", "finite_difference_analogs", "velocities",
           "velocity_analogs", "assemble", "branch_sign", "joint_residuals", "singularity",
           "solve_position", "coordinates", "jacobian", "residual", "point_position",
           "point_velocity", "point_acceleration"]
