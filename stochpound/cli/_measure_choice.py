"""Which intensity measure a risk answer should be conditioned on: the most efficient one the site's hazard is given in."""

from __future__ import annotations

import re
from typing import Any

import numpy as np


def hazard_measures(store: Any, hazard: str | None) -> dict[str, float | None]:
    """The measures the site's hazard is available in: name -> PSA period (s; None for PGA).

    A bundled curve (``--hazard NAME`` or the store's ``[hazard] bundled``):
    every bundled curve of the same site; otherwise the store's own measure.
    """
    from stochpound.analysis import bundled_curves, bundled_measure
    import stochpound.store  # noqa: F401 - registers the store accessor, ds.pound

    name = hazard if hazard in bundled_curves() else (store.pound.hazard or {}).get("bundled")
    if name:
        site = re.sub(r"_(pga|sa\d+p\d+s)$", "", name)
        measures = [bundled_measure(curve) for curve in bundled_curves() if curve.startswith(site + "_")]
    else:
        intensity = store.pound.intensity or {}
        measures = [intensity] if intensity.get("measure") in ("pga", "psa") else []
    return {("PGA" if m["measure"] == "pga" else f"PSA({m['period']:g} s)"): (None if m["measure"] == "pga" else float(m["period"])) for m in measures}


def efficient_measure_lines(store: Any, hazard: str | None) -> list[str]:
    """Lines naming, per configuration, the measure of least β of ln(closure) among those the site's hazard has, and among all candidates."""
    from stochpound.risk import measure_efficiency
    from stochpound.experiment import Experiment, periods_of_interest
    import stochpound.store  # noqa: F401 - registers the store accessor, ds.pound

    structure = periods_of_interest(Experiment(store.pound.definition))
    available = hazard_measures(store, hazard)
    candidates = {**structure, **{f"hazard {name}": period for name, period in available.items() if period is not None}}
    efficiency = measure_efficiency(store, candidates, structure, studied=store.attrs.get("studied_building"))
    beta = efficiency["beta"].sel(response="closure")
    names = {name: ("PGA" if period is None else f"PSA({period:.3g} s, hazard {name})") for name, period in available.items()}
    configurations = [d for d in beta.dims if d != "measure"]
    lines = ["", "Which measure (β: dispersion of ln(peak closure) given the measure, over the contact-free runs; smaller needs fewer motions):"]
    for index in np.ndindex(*[beta.sizes[d] for d in configurations]):
        row = beta.isel(dict(zip(configurations, index)))
        where = ", ".join(f"{d}={row[d].item()}" for d in configurations) or "all runs"
        hazard_betas = {label: float(row.sel(measure=name)) for label, name in names.items()}
        best = min(hazard_betas, key=lambda label: np.inf if np.isnan(hazard_betas[label]) else hazard_betas[label]) if hazard_betas else None
        own = row.sel(measure=[m for m in row["measure"].values if _of_configuration(str(m), structure, row)])
        overall = str(own["measure"].values[int(np.argmin(np.nan_to_num(own.values, nan=np.inf)))])
        given = "; ".join(f"{label} {value:.3f}" for label, value in hazard_betas.items())
        choice = f"most efficient the site's hazard has: {best} ({given})" if best else "the site's hazard is in no candidate measure"
        lines.append(f"  {where}: {choice}; of all candidates: {overall} ({float(np.nanmin(own.values)):.3f})")
    return lines


def _of_configuration(measure: str, structure: dict[str, float], row: Any) -> bool:
    """Whether a candidate measure belongs to the configuration ``row``: a structure period named for other variant labels does not.

    :func:`~stochpound.experiment.periods_of_interest` names a period that
    differs between grid points ``"B2 first mode (neighbour=stiff)"``; the
    measure at the other configuration's period is not this one's.
    """
    for name in structure:
        match = re.fullmatch(r".* \(([^()]*=[^()]*)\)", name)
        if match is None or not measure.endswith(f", {name})"):
            continue
        labels = dict(item.split("=", 1) for item in match.group(1).split(", "))
        return all(str(row[d].item()) == value for d, value in labels.items() if d in row.coords)
    return True
