"""Which site condition the bundled Fox Plaza curves imply: ``python -m benchmarks.site_condition [--vs30 V ...] [--flagships FILE ...]``.

The curves' source states no Vs30 (data/hazard/SOURCES.md); the risk
flagships assume 400 m/s. For each Vs30, the annual rates ν ≥ 0 of a grid of
candidate ruptures (:data:`MAGNITUDES` × :data:`DISTANCES`, strike-slip and
reverse, each model's basin depths estimated from Vs30; their P(IM > y) from
the NGA-West2 average of the conditional spectrum,
:meth:`stochpound.hazard.RuptureSite.contributions`) are fitted by
non-negative least squares (:func:`scipy.optimize.nnls`) to the relative
misfit (recomputed − site) / site of all 17 bundled curves at their tabulated
intensities whose rate lies within :data:`RATES`; then again on a wider grid
(:data:`WIDE_MAGNITUDES` × :data:`WIDE_DISTANCES`: great earthquakes far
away, beyond the site-motion model's range). Printed per grid and Vs30: the
root mean square and the largest |ln(recomputed / site)|, its mean at
PGA–0.5 s and at 1.5–5 s, and the ruptures the fit keeps (the fit
within the model's range stands in for Fox Plaza's ruptures in the answer
without a measure, ``benchmarks.measure_seeds measure_free``). A Vs30 at which no
set of ruptures gives back the curves' long periods with their short ones is
not the site's; M and Vs30 trade off (a larger earthquake farther away also
lifts the long periods), so the wider grid says how firmly.

Then, for each ``--flagships`` file, its scenario fitted at each Vs30 (the
file's ``scenario = "fitted"``, its curves and mechanism, ``vs30`` replaced)
and the ε of its stripes at that scenario: the fit alone, no pool. Why it
matters (docs/intensity.md, "The site condition the curves imply"): a stripe
of high ε needs motions the site-motion model rarely makes.
"""

from __future__ import annotations

import argparse
import logging
import re
import tempfile
from pathlib import Path

import numpy as np
from scipy.optimize import nnls

from stochpound.hazard import HazardCurve, RuptureSite, bundled_curves, bundled_measure
from stochpound.motions import Scenario, conditional_spectrum

SITE = "fox_plaza_los_angeles"
"""The bundled curves' prefix."""
MAGNITUDES = (5.75, 6.25, 6.75, 7.25, 7.75, 8.0)
"""Candidate magnitudes: within the site-motion model's M 5.5–8, so that the ruptures' motions could be simulated."""
DISTANCES = (5.0, 10.0, 20.0, 40.0, 80.0)
"""Candidate rupture distances, km: within the site-motion model's 5–100 km."""
WIDE_MAGNITUDES = MAGNITUDES + (8.25, 8.5)
"""The wider grid's magnitudes: up to the NGA-West2 models' 8.5 (their recommended limit for reverse faulting is 8)."""
WIDE_DISTANCES = DISTANCES + (150.0, 300.0)
"""The wider grid's rupture distances, km (the models' 300 km)."""
MECHANISMS = ("strike_slip", "reverse")
"""Candidate mechanisms."""
RATES = (1e-5, 0.05)
"""The curves' points fitted: annual rates of exceedance within this range, 1/yr."""
VS30 = (200.0, 250.0, 300.0, 350.0, 400.0, 500.0, 760.0)
"""Vs30 values tried by default, m/s."""
FLAGSHIPS = (Path("experiments/risk/fixed_pair.toml"), Path("experiments/risk/isolated.toml"))
"""The risk flagships."""
VS30_LINE = re.compile(r"^vs30 = [0-9.]+", re.MULTILINE)
"""A flagship's ``[site] vs30`` line."""


def site_curves() -> list[tuple[str, float | None, np.ndarray, np.ndarray]]:
    """The bundled site's 17 curves: measure kind, period (s; None for PGA), intensities (g) and annual rates (1/yr)."""
    curves = []
    for name in (n for n in bundled_curves() if n.startswith(SITE)):
        measure, curve = bundled_measure(name), HazardCurve.bundled(name)
        curves.append((measure.kind, None if measure.kind == "pga" else measure.period, curve.im, curve.rate))
    return curves


def fit_ruptures(vs30: float, curves: list[tuple[str, float | None, np.ndarray, np.ndarray]], magnitudes: tuple[float, ...] = MAGNITUDES,
                 distances: tuple[float, ...] = DISTANCES, name: str = "") -> tuple[np.ndarray, np.ndarray, RuptureSite]:
    """ln(recomputed / site) at every fitted point of ``curves`` (:func:`site_curves`' form), the point's period (0 for PGA, s)
    and the ruptures the fit keeps (a site of them named ``name``, their fitted annual rates), candidates ``magnitudes`` ×
    ``distances`` (km)."""
    candidates = [Scenario(m, r, vs30, mechanism) for mechanism in MECHANISMS for m in magnitudes for r in distances]
    site = RuptureSite.from_scenarios([(scenario, 1.0) for scenario in candidates])
    blocks, periods = [], []
    for kind, period, im, rate in curves:
        kept = (rate >= RATES[0]) & (rate <= RATES[1])
        blocks.append(site.contributions(kind, period, im[kept]) / rate[kept][:, None])
        periods += [period or 0.0] * int(kept.sum())
    matrix = np.vstack(blocks)
    rates, _ = nnls(matrix, np.ones(len(matrix)))
    fitted = RuptureSite.from_scenarios([(scenario, float(rate)) for scenario, rate in zip(candidates, rates) if rate > 0],
                                        name=name, source=f"annual rates fitted to {len(curves)} hazard curves at Vs30 {vs30:g} m/s "
                                                                 "(benchmarks.site_condition)")
    return np.log(matrix @ rates), np.array(periods), fitted


def stripe_epsilons(flagship: Path, vs30: float) -> tuple[Scenario, list[float]]:
    """The flagship's fitted scenario at ``vs30`` and the ε of its stripes' levels."""
    from stochpound.experiment import load_experiment

    text = flagship.read_text()
    if len(VS30_LINE.findall(text)) != 1:
        raise SystemExit(f"{flagship.name}: not one [site] vs30 line to replace")
    with tempfile.TemporaryDirectory() as folder:
        copy = Path(folder) / flagship.name
        copy.write_text(VS30_LINE.sub(f"vs30 = {vs30}", text))
        intensity = load_experiment(copy).intensity
    scenarios, measure = intensity.selection.scenarios, intensity.measure
    epsilons = [float(conditional_spectrum(measure.kind, measure.spectral_period, level=level, periods=[1.0], scenario=scenario).attrs["epsilon"])
                for level, scenario in zip(intensity.levels, scenarios)]
    return scenarios[0], epsilons


def main(argv: list[str] | None = None) -> int:
    """Print both tables (module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.site_condition", description=__doc__.splitlines()[0])
    parser.add_argument("--vs30", type=float, nargs="+", default=list(VS30), help="Vs30 values, m/s")
    parser.add_argument("--flagships", type=Path, nargs="*", default=list(FLAGSHIPS), help="experiment files with a fitted scenario")
    arguments = parser.parse_args(argv)
    logging.disable(logging.WARNING)  # pygmm logs a note per model call beyond its recommended range (the wider grid's M 8.25-8.5 reverse)
    print("| candidates | Vs30 (m/s) | rms of ln(recomputed / site) | largest | mean at PGA–0.5 s | mean at 1.5–5 s | ruptures kept |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    curves = site_curves()
    for label, magnitudes, distances in (("M ≤ 8, R ≤ 80 km", MAGNITUDES, DISTANCES), ("M ≤ 8.5, R ≤ 300 km", WIDE_MAGNITUDES, WIDE_DISTANCES)):
        for vs30 in arguments.vs30:
            error, periods, kept = fit_ruptures(vs30, curves, magnitudes, distances)
            print(f"| {label} | {vs30:g} | {np.sqrt(np.mean(error**2)):.2f} | {np.abs(error).max():.2f} | {error[periods <= 0.5].mean():+.2f} | "
                  f"{error[periods >= 1.5].mean():+.2f} | {len(kept)} |")
    if arguments.flagships:
        print()
        print("| flagship | Vs30 (m/s) | fitted scenario | ε of the stripes |")
        print("|---|---:|---|---|")
        for flagship in arguments.flagships:
            for vs30 in arguments.vs30:
                scenario, epsilons = stripe_epsilons(flagship, vs30)
                print(f"| {flagship.stem} | {vs30:g} | M {scenario.magnitude:g} at {scenario.distance_km:g} km, {scenario.mechanism} | "
                      f"{', '.join(f'{e:.2f}' for e in epsilons)} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
