"""The reduction method for one-degree-of-freedom machines, flywheels and start-up.

:mod:`~mechdyn.reduction.reduce` holds :func:`reduce_model` and the public names;
:mod:`~mechdyn.reduction.kinematics` the exact reduced kinematics;
:mod:`~mechdyn.reduction.machine` the reduced machine (J, dJ/dphi, M_red);
:mod:`~mechdyn.reduction.run` its motion in time, start-up and run-down;
:mod:`~mechdyn.reduction.flywheel` the steady cycle and flywheel sizing.
"""
