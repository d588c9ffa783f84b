"""The selections of the site-consistency benchmark, stripe by stripe, without running a case: ``python -m benchmarks.site_selection``.

For every configuration and conditioning measure of benchmarks/site_consistency.py
(the same experiment files; ``--max-scale-factor`` changes the limit): each
stripe's level, ε and scenario, how many of the pool's motions are within
the limit, the chosen scale factors, and the chosen set's worst differences
from its target in mean and standard deviation of ln Sa with their periods;
then the site's hazard at the other measures recomputed from the chosen,
scaled motions (the fractions of each stripe's motions above y, as
``stochpound.risk.site_consistency`` counts them on a store, and from a
lognormal ln Sa(T') per stripe with the chosen motions' mean and standard
deviation, which resolves rates below one motion in 20) and from the
stripes' conditional spectra themselves (lognormal, the fitted scenario's),
on the six stripes and on the fit's fine grid of levels, as ratios to the
site's at 10 % and 2 % in 50 years. About 15 s per configuration: the
conditional spectra and selections only.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from benchmarks.site_consistency import CONFIGURATIONS, MEASURE_ARGS, MEASURES, experiment_text


def _ratios(recomputed: np.ndarray, curve_name: str) -> str:
    """recomputed / site at the rates of 10 % and 2 % in 50 years (:func:`stochpound.risk.consistency_at_targets`)."""
    from stochpound.analysis import HazardCurve
    from stochpound.risk import consistency_at_targets

    curve = HazardCurve.bundled(curve_name)
    result = xr.Dataset({"site": ("im", curve.rate), "ratio": ("im", np.asarray(recomputed) / curve.rate)}, coords={"im": curve.im})
    return "/".join(f"{v:.2f}" for v in consistency_at_targets(result))


def _lognormal_recomputed(scaled: xr.DataArray, hazard: Any, site: Any) -> np.ndarray:
    """λ(Sa(T') > y) (1/yr) at the ``site`` curve's intensities from a lognormal ln Sa(T') per stripe: the mean and standard
    deviation of the chosen, scaled motions' (``scaled``, g, NaN where not chosen, dims intensity × record), each stripe weighted
    by the rate of its bin of the conditioning ``hazard`` (:func:`stochpound.analysis.stripe_rate_weights`, as the counts are)."""
    from scipy.special import ndtr

    from stochpound.analysis import stripe_rate_weights

    ln_sa = np.log(scaled.values)
    mean, std = np.nanmean(ln_sa, axis=1), np.nanstd(ln_sa, axis=1, ddof=1)
    weights = stripe_rate_weights(scaled["intensity"].values, hazard)
    return np.sum([w * ndtr((m - np.log(site.im)) / sd) for w, m, sd in zip(weights, mean, std)], axis=0)


def report(measure: str, configuration: str, max_scale_factor: float, folder: Path) -> None:
    """Print the stripes and the recomputed hazard of one measure and configuration."""
    from stochpound.analysis import HazardCurve, bundled_measure, hazard_consistency, stripe_rate_weights
    from stochpound.experiment import load_experiment
    from stochpound.motions import fit_levels, recomputed_hazard, selection_pool
    from stochpound.motions.records import Record, load_suite_member

    path = folder / "selection.toml"
    path.write_text(experiment_text(measure, configuration).replace("max_scale_factor = 5.0", f"max_scale_factor = {max_scale_factor}"))
    experiment = load_experiment(path)
    chosen = experiment.selection
    periods = chosen.periods
    print(f"\n{configuration}, {measure}: structure periods {', '.join(f'{t:.3g}' for t in chosen.structure)} s, range {periods[0]:.3g}-{periods[-1]:.3g} s")
    for selection, target in zip(chosen.selections, chosen.targets):
        mean_off = selection["mean_ln"].values - np.log(selection["median"].values)
        std_off = selection["std_ln"].values - selection["sigma_ln"].values
        m, s = int(np.argmax(np.abs(mean_off))), int(np.argmax(np.abs(std_off)))
        print(f"  {target.attrs['level']:.3g} g: ε {target.attrs['epsilon']:.2f}, M {target.attrs['magnitude']:g} at {target.attrs['distance_km']:g} km; "
              f"{selection.attrs['candidates']} of {selection.attrs['pool']} within the limit, scale {float(selection['scale_factor'].min()):.2f}-"
              f"{float(selection['scale_factor'].max()):.2f}; worst mean {mean_off[m]:+.2f} at {periods[m]:.2g} s, worst std {std_off[s]:+.2f} at {periods[s]:.2g} s")
    records = []
    for label, source in experiment.motions.items():
        record = load_suite_member(source.motion["record"])
        records.append(Record(label, record.dt, record.acceleration(9.81), "m/s2"))
    scale = xr.DataArray(chosen.coordinates()["selection_scale_factor"].values, dims=("intensity", "record"),
                         coords={"intensity": chosen.experiment_levels, "record": chosen.labels}).sortby("intensity")
    hazard = HazardCurve.bundled(MEASURES[measure])
    levels = scale["intensity"].values
    stripes = [dict(t.attrs) for t in sorted(chosen.targets, key=lambda t: t.attrs["level"])]
    fine = fit_levels(levels, hazard.support[1], hazard.support[0])
    conditioning = bundled_measure(MEASURES[measure])
    lines = []
    for other, name in MEASURES.items():
        if other == measure:
            continue
        kind, period = MEASURE_ARGS[other]
        unscaled = selection_pool(records, [1.0], kind, period)["intensity"].values
        scaled = scale * xr.DataArray(unscaled, dims="record", coords={"record": chosen.labels})
        from_motions = hazard_consistency(scaled, hazard, HazardCurve.bundled(name))
        lognormal = _lognormal_recomputed(scaled, hazard, HazardCurve.bundled(name))
        site = [(period, HazardCurve.bundled(name).im, HazardCurve.bundled(name).rate)]
        scenarios = [{key: s[key] for key in ("magnitude", "distance_km", "vs30", "mechanism")} for s in stripes]
        on_stripes = recomputed_hazard(conditioning.kind, conditioning.period, levels, stripe_rate_weights(levels, hazard), scenarios, site)[0]
        nearest = [scenarios[int(np.argmin(np.abs(np.log(levels) - np.log(x))))] for x in fine]
        on_fine = recomputed_hazard(conditioning.kind, conditioning.period, fine, stripe_rate_weights(fine, hazard), nearest, site)[0]
        lines.append(f"{other}: motions {_ratios(from_motions['recomputed'].values, name)} (lognormal {_ratios(lognormal, name)}), spectra on the stripes {_ratios(on_stripes, name)}, "
                     f"on the fine grid {_ratios(on_fine, name)}")
    print("  recomputed / site at 10 %/2 % in 50 yr:", "; ".join(lines))


def main(argv: list[str] | None = None) -> None:
    """Print every configuration's and measure's stripes."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--measures", nargs="+", default=list(MEASURES), choices=list(MEASURES))
    parser.add_argument("--configurations", nargs="+", default=list(CONFIGURATIONS), choices=list(CONFIGURATIONS))
    parser.add_argument("--max-scale-factor", type=float, default=5.0)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        for configuration in args.configurations:
            for measure in args.measures:
                report(measure, configuration, args.max_scale_factor, Path(folder))


if __name__ == "__main__":
    main()
