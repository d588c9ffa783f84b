"""Design strength: a code-designed building's storey yield shears (ASCE 7-16 equivalent lateral force).

The formulas are the ``asce7-16`` package's (``seismic_response_coeff``:
§12.8.1.1 with its bounds; ``vertical_force_dist``: §12.8.3), not written
again here. The package is imported on first use (it imports ``requests``
for its USGS client, which a simulation never needs).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stochpound.motions import DEFAULT_G


def design_yield_shears(mass: Sequence[float], storey_height: Sequence[float], *, period: float, sds: float, sd1: float, r: float,
                        overstrength: float, importance: float = 1.0, s1: float = 0.0, long_period: float = 8.0,
                        g: float = DEFAULT_G) -> np.ndarray:
    """The storey yield shears F_y (N) of a shear building designed by ASCE 7-16's equivalent lateral force procedure.

    The design base shear is V = C_s W (§12.8.1) with W = g Σ m the seismic
    weight of the floors and C_s = S_DS / (R / I_e), bounded above by
    S_D1 / (T R / I_e) (or S_D1 T_L / (T² R / I_e) beyond T_L) and below by
    max(0.044 S_DS I_e, 0.01) and, where S_1 ≥ 0.6 g, 0.5 S_1 / (R / I_e).
    The floors carry F_x = C_vx V with C_vx = w_x h_x^k / Σ w_i h_i^k
    (§12.8.3: h_x the floor's height above the base, k = 1 up to T = 0.5 s,
    2 from 2.5 s, linear between). A storey's design shear is the sum of the
    forces of the floors above it, and its yield shear that times the
    overstrength Ω0: F_y,i = Ω0 Σ_{x ≥ i} F_x, the ``yield_force`` of a scene's
    ``[[building]]``.

    Parameters
    ----------
    mass : sequence of float
        Floor masses, kg, floor 1 (lowest) upwards.
    storey_height : sequence of float
        Storey heights, m, storey 1 upwards (floor x stands at their sum up to x).
    period : float
        The design fundamental period T, s (ASCE 7-16 §12.8.2: the building's
        computed period, at most C_u T_a, or T_a).
    sds, sd1 : float
        Design spectral accelerations S_DS (short periods) and S_D1 (1 s), in g.
    r : float
        Response modification coefficient R (> 0).
    overstrength : float
        Overstrength factor Ω0 (≥ 1): the ratio of the yield shear to the design shear.
    importance : float
        Seismic importance factor I_e (> 0).
    s1 : float
        Mapped MCE_R spectral acceleration S_1 at 1 s, in g (only its lower bound on C_s uses it).
    long_period : float
        Long-period transition period T_L, s.
    g : float
        Gravitational acceleration, m/s².

    Returns
    -------
    np.ndarray
        The yield shear of each storey, N, storey 1 upwards.
    """
    mass, height = np.asarray(mass, float), np.asarray(storey_height, float)
    if mass.ndim != 1 or len(mass) == 0 or np.any(mass <= 0.0):
        raise ValueError(f"mass: must be one or more floor masses > 0 kg, got {mass.tolist()!r}")
    if height.shape != mass.shape or np.any(height <= 0.0):
        raise ValueError(f"storey_height: must be {len(mass)} storey heights > 0 m, got {height.tolist()!r}")
    for name, value, low in (("period", period, 0.0), ("r", r, 0.0), ("importance", importance, 0.0), ("long_period", long_period, 0.0),
                             ("sds", sds, 0.0), ("sd1", sd1, 0.0)):
        if not np.isfinite(value) or value <= low:
            raise ValueError(f"{name}: must be > {low:g}, got {value!r}")
    if not np.isfinite(overstrength) or overstrength < 1.0:
        raise ValueError(f"overstrength: must be ≥ 1, got {overstrength!r}")
    from asce7_16 import seismic

    weight = g * mass
    coefficient = seismic.seismic_response_coeff(r, importance, sds, sd1, s1, period, long_period)
    forces = seismic.vertical_force_dist(weight, np.cumsum(height), period) * coefficient * weight.sum()
    return overstrength * np.cumsum(forces[::-1])[::-1]
