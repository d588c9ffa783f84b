"""Soil presets for the Kanai–Tajimi and Clough–Penzien filters.

Values of Der Kiureghian & Neuenhofer (1992), "Response spectrum method for
multi-support seismic excitations", Earthquake Engineering and Structural
Dynamics 21(8), 713–740, widely reused for firm, medium and soft soil:

======  =========  ======  =========  ======
soil    ω_g rad/s  ζ_g     ω_f rad/s  ζ_f
======  =========  ======  =========  ======
firm    15.0       0.6     1.5        0.6
medium  10.0       0.4     1.0        0.6
soft    5.0        0.2     0.5        0.6
======  =========  ======  =========  ======

(ω_f = ω_g / 10 and ζ_f = 0.6 throughout.)
"""

from __future__ import annotations

from dataclasses import dataclass

SOURCE = (
    "A. Der Kiureghian and A. Neuenhofer (1992), Response spectrum method for multi-support "
    "seismic excitations, Earthquake Engng Struct. Dyn. 21(8):713-740"
)


@dataclass(frozen=True)
class SoilPreset:
    """Filter parameters of one soil type (frequencies in rad/s)."""

    name: str
    omega_g: float
    zeta_g: float
    omega_f: float
    zeta_f: float
    source: str = SOURCE

    def kanai_tajimi(self) -> dict[str, float]:
        """Keyword arguments for :func:`stochpound.motions.kanai_tajimi`."""
        return {"omega_g": self.omega_g, "zeta_g": self.zeta_g}

    def clough_penzien(self) -> dict[str, float]:
        """Keyword arguments for :func:`stochpound.motions.clough_penzien`."""
        return {**self.kanai_tajimi(), "omega_f": self.omega_f, "zeta_f": self.zeta_f}


SOIL_PRESETS: dict[str, SoilPreset] = {
    "firm": SoilPreset("firm", 15.0, 0.6, 1.5, 0.6),
    "medium": SoilPreset("medium", 10.0, 0.4, 1.0, 0.6),
    "soft": SoilPreset("soft", 5.0, 0.2, 0.5, 0.6),
}


def soil_preset(name: str) -> SoilPreset:
    """The preset ``"firm"``, ``"medium"`` or ``"soft"``."""
    try:
        return SOIL_PRESETS[name]
    except KeyError:
        raise ValueError(f"soil: must be one of {', '.join(SOIL_PRESETS)}; got {name!r}") from None
