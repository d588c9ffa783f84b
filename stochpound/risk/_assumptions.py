"""The structural model's idealisations a risk answer rests on, read off the scenes that ran, each said where it applies only.

:func:`scene_assumptions` gives, from one scene per configuration of a store
(its first contact-free case that ran) and its definition, in words:

* the storeys: each building's storey heights where given (the drift ratios,
  their limit states and P-Δ rest on them), its damping ratio, its yield
  shears and hardening or its linear storeys, and that no storey loses
  strength or collapses (the model has no degradation or collapse);
* a sliding base's friction law (Coulomb: one kinetic μ, with no dependence on
  velocity, pressure or temperature; or velocity-dependent) and its pendulum;
* the moat walls: clearance, stiffness (and its frequency on the mass it stops),
  restitution, in the configurations that have them;
* the gap identity that gives g* from the contact-free runs, with the walls'
  where the scene has walls;
* the simulated motions that ran (``[site] simulated_motions``): their
  site-motion model and its calibration (:func:`simulated_motions_text`, from the store).

The chapter 17 design's spectrum and assumptions are the design rules' own
(``stochpound.risk._design_rules.design_assumptions``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from stochpound._plurals import counted
from stochpound.model import Scene
from stochpound.model.building import Building

def scene_assumptions(scenes: Mapping[tuple[Any, ...], Scene]) -> dict[str, str]:
    """What the answer rests on of the structural model and the motions, in words, each key present only where it applies.

    Parameters
    ----------
    scenes : mapping
        One scene per configuration (``stochpound.risk._inputs.configuration_scenes``); empty: the gap identity only.

    Returns
    -------
    dict of str to str
        ``storeys`` (with scenes), ``sliding base`` (a building on one), ``moat walls`` (a scene with walls) and ``gap identity``
        (always), in that order (the simulated motions that ran: :func:`simulated_motions_text`).
    """
    said: dict[str, str] = {}
    every = list(scenes.values())
    if every:
        buildings = [building for scene in every for building in scene.buildings]
        said["storeys"] = "; ".join(_distinct(_storeys(building, scene.g) for scene in every for building in scene.buildings)) + (
            ". No storey loses strength, degrades or collapses (no such model): a drift beyond what a real frame survives is "
            "computed as if it did" if any(b.yield_force is not None for b in buildings) else
            ". The storeys stay linear at any amplitude (no yielding, strength loss or collapse)")
    bases = _bases([(building, scene.g) for scene in every for building in scene.buildings if building.base is not None])
    if bases:
        said["sliding base"] = bases
    walls = _distinct(_wall(scene, wall) for scene in every for wall in scene.walls)
    if walls:
        said["moat walls"] = "; ".join(walls) + " (each an impact element against a rigid wall moving with the ground)"
    said["gap identity"] = ("a run with gap g pounds if and only if its contact-free twin's peak closure reaches g (the two are the same run "
                            "until the first impact, an open contact exerting no force), so g*, the fragilities and the code rules' rates "
                            "come from the contact-free runs; what pounding does after the first impact is not part of them"
                            + ("; likewise a moat wall is reached if and only if the wall-free run's base displacement reaches its "
                               "clearance" if walls else ""))
    return said


def simulated_motions_text(simulated: int, ran: int, model: str, calibration: str) -> str:
    """The ``simulated`` motions of the ``ran`` that ran (``[site] simulated_motions`` chosen into the stripes) with their
    site-motion ``model`` and its ``calibration``, in words; "" where none ran."""
    if not simulated:
        return ""
    return (f"{counted(simulated, 'simulated motion')} of the {ran} that ran ({model} site-motion model, calibration {calibration}): "
            "their spectra, durations and variability are the model's as calibrated, not recorded ones")


def _distinct(texts: Iterable[str]) -> list[str]:
    return list(dict.fromkeys(texts))


def _numbers(values: Iterable[float], digits: int = 3) -> str:
    return ", ".join(f"{v:.{digits}g}" for v in values)


def _storeys(building: Building, g: float) -> str:
    """One building's storeys in words: heights, damping, yield shears or linear storeys, P-Δ."""
    heights = (f"storey heights {_numbers(building.storey_height)} m (the drift ratios, their limit states"
               f"{' and P-Δ' if building.p_delta else ''} rest on them)" if building.storey_height else "no storey heights (no drift ratios)")
    damping = f", damping ratio {100 * building.damping_ratio:g} %" if building.damping_ratio is not None else ", damping as given (no ratio)"
    if building.yield_force is not None:
        weight = g * sum(building.mass)
        strength = (f"bilinear storeys, F_y = {_numbers([f / 1e3 for f in building.yield_force], 4)} kN (first storey "
                    f"{building.yield_force[0] / weight:.3g} W), "
                    f"hardening {100 * building.hardening:g} %{', P-Δ' if building.p_delta else ', no P-Δ'}")
    else:
        strength = "linear elastic storeys (no yielding)"
    return f"{building.name}: {heights}{damping}, {strength}"


def _bases(bases: list[tuple[Building, float]]) -> str:
    """The sliding bases in words, one per building and law, its friction coefficients over the configurations listed."""
    grouped: dict[str, list[float]] = {}
    for building, g in bases:
        grouped.setdefault(_base(building, g), []).append(building.base.mu)
    return "; ".join(text.replace("μ = {mu}", f"μ = {_numbers(dict.fromkeys(mus))}") for text, mus in grouped.items())


def _base(building: Building, g: float) -> str:
    """A sliding base's friction law and restoring force in words, its coefficient left as ``μ = {mu}`` (:func:`_bases`)."""
    base = building.base
    if base.mu_fast is None:
        static = "" if base.mu_static == base.mu else f", static {base.mu_static:g}"
        law = (f"Coulomb friction, μ = {{mu}}{static}, the same at every velocity, pressure and temperature (no heating, wear or "
               "velocity dependence)")
    else:
        law = f"velocity-dependent friction, μ = {{mu}} (slow) to {base.mu_fast:g} (fast), rate {base.mu_rate:g} s/m"
    if base.radius is not None:
        restoring = f"on a friction pendulum of radius {base.radius:g} m (T = {2 * math.pi * math.sqrt(base.radius / g):.3g} s)"
    elif base.restoring_stiffness:
        restoring = f"with a restoring stiffness {base.restoring_stiffness:.3g} N/m"
    else:
        restoring = "on a flat slider (no restoring force)"
    return f"{building.name}: {law}, {restoring}, base mass {base.mass:g} kg"


def _wall(scene: Scene, wall: Any) -> str:
    """A wall in words: where, its clearance, its stiffness and the frequency it gives the mass it stops, its restitution."""
    building = scene.buildings[wall.building]
    mass = building.base.mass if wall.level == 0 and building.base is not None else building.mass[max(wall.level - 1, 0)]
    where = "at the base" if wall.level == 0 else f"at level {wall.level}"
    restitution = f", restitution {wall.restitution:g}" if wall.restitution is not None else ""
    clearance = f"clearance {wall.gap:g} m" if math.isfinite(wall.gap) else "clearance as the grid sets it"
    return (f"{building.name} {where}, {clearance}, stiffness {wall.stiffness:.3g} N/m (√(k/m) = "
            f"{math.sqrt(wall.stiffness / mass):.3g} rad/s on {mass:g} kg){restitution}, law {wall.law}")
