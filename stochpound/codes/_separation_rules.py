"""Code separation rules (ABS, SRSS, DDC), evaluated per run from the same contact-free run.

Each rule combines u1, u2, the peak displacements relative to the ground of
the two floors at a contact (m), into the gap it asks for:

- ABS: u1 + u2, an upper bound of the peak closure (u1, u2 and the closure
  all located on the solution);
- SRSS: sqrt(u1² + u2²) (ASCE 7's δ_MT; Eurocode 8, which allows 0.7 of it
  where the floor levels of the two buildings coincide);
- DDC, the double difference combination (Jeng et al. 1992; Penzien 1997):
  sqrt(u1² + u2² − 2 ρ u1 u2), ρ the correlation of the two displacement
  histories or, for linear buildings, the CQC coefficient of their modes.

:func:`contact_demands` reads u1, u2, ρ and the peak closure D of every
contact off one run; :func:`separation_rules` turns them into each rule's
gap, which :func:`stochpound.analysis._separation.rule_exceedance` judges
against D over an ensemble (docs/separation.md).
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy.linalg import eigh

from stochpound.stats import correlation
from stochpound.model.building import Building, storey_matrix
from stochpound.model.scene import Scene

EC8_REDUCTION = 0.7
"""Eurocode 8's factor on the SRSS separation where the floor levels of the two buildings coincide (EN 1998-1 §4.4.2.7(3))."""
RULES = ("abs", "srss", "srss_reduced", "ddc", "ddc_cqc")
"""Names of the rules on the ``rule`` dimension of :func:`separation_rules` (``ddc_cqc`` only when given a CQC ρ)."""


STORE_NAMES = {
    "peak_closure": "peak_contact_closure",
    "peak_displacement_left": "contact_peak_displacement_left",
    "peak_displacement_right": "contact_peak_displacement_right",
    "correlation": "contact_correlation",
}
"""Name of each variable of :func:`contact_demands` in an experiment store (its per-case summaries)."""


def store_contact_demands(store: xr.Dataset) -> xr.Dataset:
    """The :func:`contact_demands` of every case of an experiment store (its names; lazy on a dask-backed store)."""
    return store[list(STORE_NAMES.values())].rename({stored: name for name, stored in STORE_NAMES.items()})


def contact_demands(run: xr.Dataset, dim: str = "time") -> xr.Dataset:
    """The inputs of the separation rules at every contact of a run.

    Parameters
    ----------
    run : xarray.Dataset
        A result of :func:`stochpound.simulate` (``total_displacement``, the
        ``contact_*`` description, ``peak_contact_closure`` and
        ``peak_contact_displacement_left``/``_right``); run it contact-free
        (every gap ``inf``) for the rules of an ensemble: a contact with a
        finite gap has no located u1, u2 (NaN, and so are its rules).
    dim : str
        The time dimension.

    Returns
    -------
    xarray.Dataset
        Per contact: ``peak_displacement_left`` and ``peak_displacement_right``
        (u1, u2: the largest absolute displacement y of the contact's floors
        relative to the ground, m), ``correlation`` (ρ, Pearson correlation of the
        two floors' y over the output samples) and ``peak_closure`` (D, the largest
        y_left − y_right, m). u1, u2 and D are all located on the solution
        (the engine's monitors), so ABS = u1 + u2 ≥ D holds by construction.
    """
    displacement = run["total_displacement"]
    left = _floor_history(displacement, run["contact_left"], run["contact_left_floor"])
    right = _floor_history(displacement, run["contact_right"], run["contact_right_floor"])
    return xr.Dataset(
        {
            "peak_displacement_left": run["peak_contact_displacement_left"].assign_attrs(units="m", long_name="peak |y| of the contact's left floor (u1)"),
            "peak_displacement_right": run["peak_contact_displacement_right"].assign_attrs(units="m", long_name="peak |y| of the contact's right floor (u2)"),
            "correlation": correlation(left, right, dim).assign_attrs(long_name="correlation of the two floors' displacement histories (rho)"),
            "peak_closure": run["peak_contact_closure"],
        }
    )


def separation_rules(demands: xr.Dataset, cqc: xr.DataArray | None = None, reduction: float = EC8_REDUCTION) -> xr.DataArray:
    """Each rule's gap at every contact, from :func:`contact_demands`.

    Parameters
    ----------
    demands : xarray.Dataset
        From :func:`contact_demands` (or their concatenation over realizations).
    cqc : xarray.DataArray, optional
        A CQC correlation per contact (e.g. :func:`fixed_base_cqc`); adds the
        rule ``ddc_cqc`` (NaN where it is NaN).
    reduction : float
        The factor of ``srss_reduced`` (Eurocode 8: 0.7 where floor levels
        coincide, as they do for the floor-to-floor contacts of a scene).

    Returns
    -------
    xarray.DataArray
        Gaps (m) on a new dimension ``rule``: ``abs``, ``srss`` (ASCE 7's
        δ_MT), ``srss_reduced``, ``ddc`` (ρ from the histories) and, with
        ``cqc``, ``ddc_cqc``.
    """
    if not 0.0 < reduction <= 1.0:
        raise ValueError(f"reduction: must be in (0, 1], got {reduction}")
    u1, u2 = demands["peak_displacement_left"], demands["peak_displacement_right"]
    gaps = [abs_rule(u1, u2), srss_rule(u1, u2), reduction * srss_rule(u1, u2), ddc_rule(u1, u2, demands["correlation"])]
    if cqc is not None:
        gaps.append(ddc_rule(u1, u2, cqc))
    rules = xr.concat(gaps, dim="rule", coords="minimal", compat="override", join="outer")
    return rules.assign_coords(rule=list(RULES[: len(gaps)])).assign_attrs(units="m", long_name="gap asked for by the separation rule", srss_reduction=reduction)


def abs_rule(u1: xr.DataArray, u2: xr.DataArray) -> xr.DataArray:
    """ABS: u1 + u2 (m), the largest closure two floors with peaks u1, u2 can reach."""
    return u1 + u2


def srss_rule(u1: xr.DataArray, u2: xr.DataArray) -> xr.DataArray:
    """SRSS: sqrt(u1² + u2²) (m), ASCE 7's δ_MT and Eurocode 8's separation (before its 0.7 reduction)."""
    return np.sqrt(u1**2 + u2**2)


def ddc_rule(u1: xr.DataArray, u2: xr.DataArray, rho: xr.DataArray) -> xr.DataArray:
    """DDC: sqrt(u1² + u2² − 2 ρ u1 u2) (m), the double difference combination (Jeng et al. 1992; Penzien 1997).

    For two histories of one frequency, y1 = u1 sin(ωt) and
    y2 = u2 sin(ωt + φ) (ρ = cos φ), it is exactly the peak of y1 − y2.
    Rounding below 0 (ρ = 1, u1 = u2) is clipped to 0.
    """
    return np.sqrt(np.maximum(u1**2 + u2**2 - 2.0 * rho * u1 * u2, 0.0))


def cqc_coefficient(omega_i: ArrayLike, zeta_i: ArrayLike, omega_j: ArrayLike, zeta_j: ArrayLike) -> np.ndarray:
    """CQC correlation coefficient of two linear oscillators (Der Kiureghian 1981).

    ρ_ij = 8 sqrt(ζ_i ζ_j ω_i ω_j) (ζ_i ω_i + ζ_j ω_j) ω_i ω_j
           / [(ω_i² − ω_j²)² + 4 ζ_i ζ_j ω_i ω_j (ω_i² + ω_j²) + 4 (ζ_i² + ζ_j²) ω_i² ω_j²],

    the correlation of the responses of oscillators (ω_i, ζ_i) and
    (ω_j, ζ_j) to the same white-noise excitation (A. Der Kiureghian, "A
    response spectrum method for random vibration analysis of MDF systems",
    Earthquake Engineering and Structural Dynamics 9, 419–435, 1981). With
    r = ω_j/ω_i and ζ_i = ζ_j = ζ it is
    8 ζ² (1 + r) r^{3/2} / [(1 − r²)² + 4 ζ² r (1 + r)²]; 1 for identical oscillators.

    Parameters
    ----------
    omega_i, omega_j : array_like
        Natural circular frequencies, rad/s (≥ 0).
    zeta_i, zeta_j : array_like
        Damping ratios (≥ 0, not both 0). Broadcast like numpy arrays.

    Returns
    -------
    numpy.ndarray
        ρ_ij, in [0, 1].
    """
    omega_i, zeta_i, omega_j, zeta_j = (np.asarray(value, dtype=float) for value in (omega_i, zeta_i, omega_j, zeta_j))
    product = omega_i * omega_j
    numerator = 8.0 * np.sqrt(zeta_i * zeta_j * product) * (zeta_i * omega_i + zeta_j * omega_j) * product
    denominator = (omega_i**2 - omega_j**2) ** 2 + 4.0 * zeta_i * zeta_j * product * (omega_i**2 + omega_j**2) + 4.0 * (zeta_i**2 + zeta_j**2) * product**2
    return numerator / denominator


def fixed_base_cqc(scene: Scene) -> xr.DataArray:
    """CQC coefficient of the fundamental modes of every contact's two fixed-base buildings.

    Only mode 1 of each building is used, as in the DDC of two single-mode
    buildings: in a shear building it moves every floor the same way, so ρ
    does not depend on the contact's floors; the higher modes are neglected.
    Each mode's damping ratio is φᵀCφ / (2ω) with the mass-normalised shape
    φ of the undamped fixed-base building (exact for classical damping such
    as C = a₁K; the diagonal term otherwise).

    Parameters
    ----------
    scene : Scene
        The scene whose contacts are judged.

    Returns
    -------
    xarray.DataArray
        ρ per contact (dimension ``contact``); NaN where either building
        stands on a sliding base (no linear theory applies).
    """
    modes = [None if building.isolated else fundamental_mode(building) for building in scene.buildings]
    values = []
    for contact in scene.contacts:
        left, right = modes[contact.left], modes[contact.right]
        values.append(np.nan if left is None or right is None else float(cqc_coefficient(*left, *right)))
    return xr.DataArray(values, dims="contact", coords={"contact": np.arange(len(values))},
                        attrs={"units": "1", "long_name": "CQC coefficient of the two buildings' fixed-base mode 1"})


def fundamental_mode(building: Building) -> tuple[float, float]:
    """Circular frequency (rad/s) and damping ratio of mode 1 of ``building`` on a fixed base."""
    eigenvalues, shapes = eigh(storey_matrix(np.asarray(building.stiffness, float)), np.diag(building.mass))
    omega, shape = float(np.sqrt(eigenvalues[0])), shapes[:, 0]
    return omega, float(shape @ storey_matrix(np.asarray(building.damping, float)) @ shape / (2.0 * omega))


def _floor_history(displacement: xr.DataArray, building: xr.DataArray, floor: xr.DataArray) -> xr.DataArray:
    """``displacement`` of each contact's floor (one building and floor per contact), m."""
    return displacement.sel(building=building, floor=floor).drop_vars(["building", "floor"])
