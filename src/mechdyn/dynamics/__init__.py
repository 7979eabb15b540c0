"""One mode of a mechanism: its system, equations (exact and analogs), Lagrange II,
the compiled kernel, reactions and singular positions."""
