"""Friction in the pairs, written once for every analysis.

:mod:`~mechdyn.friction.law` the friction law of revolute and prismatic pairs and the
friction set of a model; :mod:`~mechdyn.friction.kinetostatic` friction coupled to
the reactions of one position (kinetostatics, the reactions of a run);
:mod:`~mechdyn.friction.forward` friction in forward dynamics (the coupled solve,
stick and slip); :mod:`~mechdyn.friction.stick_slip` the state of every Coulomb pair
at a switching instant; :mod:`~mechdyn.friction.ignored` the warning of an analysis
that does not model friction yet.
"""
