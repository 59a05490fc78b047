"""Slow, obviously correct twins of the numba kernels, for the kernel tests."""
