"""Evaluators over data: the constraint rows (NumPy, batched; and the Numba twin), the
packed loads and the small dense linear algebra of the compiled kernels."""
