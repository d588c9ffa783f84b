"""Solvers of the hybrid pounding model (each advances the same modes and events)."""
