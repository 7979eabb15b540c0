"""Kinetostatics: inverse dynamics for a prescribed motion.

:mod:`~mechdyn.kinetostatics.inverse` holds :func:`kinetostatics`, the user's entry;
:mod:`~mechdyn.kinetostatics.mode` the analysis in one mode;
:mod:`~mechdyn.kinetostatics.switched` a switched trajectory segment by segment;
:mod:`~mechdyn.kinetostatics.prescribed` the poses, rates and accelerations of a
prescribed motion.
"""
