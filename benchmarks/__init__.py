"""Benchmarks of mechdyn: ``python -m benchmarks`` (or ``make bench``) runs them all."""
