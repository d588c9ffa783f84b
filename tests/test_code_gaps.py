"""Code separations from the design analysis, against hand computations with the codes' formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochpound.risk import (Asce7Design, Ec8Design, asce7_inelastic_displacement, asce7_isolator_displacement, ec8_design_displacement,
                             modal_floor_displacements, srss_separation)
from stochpound.codes import damping_coefficient
from stochpound.model.building import Building

G = 9.81


def _sdof(period: float, mass: float = 1.0e5) -> Building:
    stiffness = mass * (2.0 * math.pi / period) ** 2
    return Building("B", (mass,), (stiffness,), (0.0,))


def test_asce7_separation_of_two_sdof_buildings_by_hand():
    # S_DS 1.0 g, S_D1 0.6 g: T_0 = 0.12 s, T_S = 0.6 s; T = 0.5 s sits on the plateau, S_a = S_DS.
    design = Asce7Design(sds=1.0, sd1=0.6, tl=8.0, r=8.0, cd=5.5, ie=1.0)
    elastic = modal_floor_displacements(_sdof(0.5), design=design, g=G)
    by_hand = 1.0 * G / (2.0 * math.pi / 0.5) ** 2
    assert elastic[0] == pytest.approx(by_hand, rel=1e-12)
    delta_m = asce7_inelastic_displacement(elastic, design)[0]
    assert delta_m == pytest.approx(5.5 * (by_hand / 8.0) / 1.0, rel=1e-12)  # eq. 12.12-1
    # T = 1.5 s on the descending branch S_D1 / T; I_e = 1.5 enters delta_max and delta_M.
    stiff = Asce7Design(sds=1.0, sd1=0.6, tl=8.0, r=8.0, cd=5.5, ie=1.5)
    other = asce7_inelastic_displacement(modal_floor_displacements(_sdof(1.5), design=stiff, g=G), stiff)[0]
    by_hand_other = 5.5 * ((0.6 / 1.5) * G / (2.0 * math.pi / 1.5) ** 2 / (8.0 / 1.5)) / 1.5
    assert other == pytest.approx(by_hand_other, rel=1e-12)
    assert srss_separation(delta_m, other) == pytest.approx(math.sqrt(delta_m**2 + by_hand_other**2), rel=1e-15)  # eq. 12.12-2


def test_modal_displacements_of_a_two_storey_building_by_hand():
    # Equal masses m and storey stiffnesses k: omega^2 = (k/m)(3 -+ sqrt 5)/2, shapes (1, (1 +- sqrt 5)/2).
    m, k = 2.0e4, 3.0e7
    building = Building("B", (m, m), (k, k), (0.0, 0.0))
    spectrum = np.array([0.8, 0.5])  # g, per mode
    golden = (1.0 + math.sqrt(5.0)) / 2.0
    floors = []
    for n, (ratio, shape2) in enumerate((((3 - math.sqrt(5)) / 2, golden), ((3 + math.sqrt(5)) / 2, 1.0 - golden))):
        shape = np.array([1.0, shape2])
        gamma = shape.sum() * m / (m * shape @ shape)
        floors.append(gamma * shape * spectrum[n] * G / (ratio * k / m))
    by_hand = np.sqrt(floors[0] ** 2 + floors[1] ** 2)
    np.testing.assert_allclose(modal_floor_displacements(building, spectrum, g=G), by_hand, rtol=1e-12)


def test_ec8_design_displacement_by_hand():
    # Ground C (S 1.15, T_B 0.2, T_C 0.6, T_D 2.0), a_g 0.3 g, q 4, T = 1.0 s: S_d = a_g S 2.5/q T_C/T (eq. 3.15).
    design = Ec8Design(ag=0.3, ground="C", q=4.0)
    sd = 0.3 * 1.15 * 2.5 / 4.0 * 0.6 / 1.0
    assert design.spectrum(np.array([1.0]))[0] == pytest.approx(sd, rel=1e-12)
    d_e = modal_floor_displacements(_sdof(1.0), design=design, g=G)
    d_s = ec8_design_displacement(d_e, design)[0]
    assert d_s == pytest.approx(4.0 * sd * G / (2.0 * math.pi) ** 2, rel=1e-12)  # eq. 4.23
    # the lower bound beta a_g (eq. 3.16) governs far out; the rising branch starts at 2/3 a_g S (eq. 3.13)
    assert design.spectrum(np.array([4.0]))[0] == pytest.approx(0.2 * 0.3, rel=1e-12)
    assert design.spectrum(np.array([0.0]))[0] == pytest.approx(0.3 * 1.15 * 2.0 / 3.0, rel=1e-12)


def test_asce7_isolator_displacement_solves_eq_17_5_1():
    displacement, period, damping = asce7_isolator_displacement(1.0e6, mu=0.05, radius=2.24, sm1=1.2, g=G)
    stiffness = 1.0e6 / 2.24 + 0.05 * 1.0e6 / displacement
    assert period == pytest.approx(2.0 * math.pi * math.sqrt(1.0e6 / (stiffness * G)), rel=1e-9)
    assert damping == pytest.approx(2.0 * 0.05 / (math.pi * (0.05 + displacement / 2.24)), rel=1e-9)
    assert displacement == pytest.approx(G * 1.2 * period / (4.0 * math.pi**2 * damping_coefficient(damping)), rel=1e-9)
    assert damping_coefficient(0.15) == pytest.approx(1.35)  # Table 17.5-1 between 10 % (1.2) and 20 % (1.5)


@pytest.mark.parametrize("field, kwargs, message", [
    ("r", dict(sds=1.0, sd1=0.6, tl=8.0, r=0.0, cd=5.5), "design.r: must be a positive number"),
    ("q", dict(ag=0.3, ground="C", q=0.5), "design.q: must be >= 1"),
    ("ground", dict(ag=0.3, ground="F", q=2.0), "design.ground: must be one of A, B, C, D, E"),
])
def test_bad_design_is_a_one_line_error(field, kwargs, message):
    cls = Asce7Design if "sds" in kwargs else Ec8Design
    with pytest.raises(ValueError, match=message):
        cls(**kwargs)
