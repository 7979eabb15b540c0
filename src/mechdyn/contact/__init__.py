"""The solvers of unilateral contact problems: complementarity and compliance.

:mod:`~mechdyn.contact.complementarity` the LCP of contact forces and
impulses; :mod:`~mechdyn.contact.compliance` static indeterminacy by influence
coefficients (the cyclic-automata method).  The gaps of a run and its impacts are the
segment loop's (:mod:`mechdyn.simulate.gaps`, :mod:`mechdyn.simulate.impact`).
"""
