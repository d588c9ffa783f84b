"""The Arias intensity of accelerations linear between samples, and the toolkit's default g.

With a_g linear in every step (a_k + s τ, 0 ≤ τ ≤ h), ∫ a_g² dt over a step is
h (a_k² + a_k a_{k+1} + a_{k+1}²)/3 exactly, and I_a = π/(2g) ∫ a_g² dt.
This module imports nothing of the toolkit: the intensity measures
(``_measures``) and the records' statistics (``records/_statistics``) both
read it, so neither imports the other.
"""

from __future__ import annotations

import numpy as np

#: The acceleration of gravity used for records stored in g, m/s² (the toolkit's default).
DEFAULT_G = 9.81


def squared_integrals(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """∫ a_g² dt over every step, h (a_k² + a_k a_{k+1} + a_{k+1}²)/3 (m²/s³)."""
    a = np.asarray(acceleration, dtype=np.float64)
    left, right = a[:-1], a[1:]
    return float(dt) * (left * left + left * right + right * right) / 3.0


def arias_intensity(acceleration: np.ndarray, dt: float, g: float = DEFAULT_G) -> float:
    """Arias intensity π/(2g) ∫ a_g² dt (m/s) of samples in m/s² linear between them (``dt`` in s, ``g`` in m/s²)."""
    return np.pi / (2.0 * g) * float(np.sum(squared_integrals(acceleration, dt)))
