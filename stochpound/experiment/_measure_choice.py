"""Which intensity measure a risk answer should be conditioned on: the most efficient one the site's hazard is given in.

For every configuration of a store, β of ln(peak closure) given each
candidate measure (:func:`stochpound.risk.measure_efficiency`, over the
contact-free runs): the measures the site's hazard is available in (every
bundled curve of the store's site, or the store's own measure) and PSA at
the structure's own periods (:func:`periods_of_interest`), PGA, PGV and
Sa_avg. ``stochpound risk`` prints it and the report's Risk section shows it.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import pandas as pd

from stochpound.experiment._site import periods_of_interest
from stochpound.motions import Measure
from stochpound.store import Label

#: Why no measure is named most efficient when a stripe ran one motion (``measure_choice``'s ``unjudged``).
ONE_MOTION = ("efficiency cannot be judged from one motion per stripe (or one motion in all): β is the scatter of the motions "
              "about each measure's fit, and one motion has none")


def hazard_measures(store: Any, hazard: str | None = None) -> dict[str, float | None]:
    """The measures the site's hazard is available in: name -> PSA period (s; None for PGA).

    A bundled curve (``hazard`` or the store's ``[hazard] bundled``):
    every bundled curve of the same site; otherwise the store's own measure.
    """
    from stochpound.hazard import bundled_curves, bundled_measure, bundled_site_curves

    name = hazard if hazard in bundled_curves() else (store.pound.hazard.bundled if store.pound.hazard is not None else None)
    if name:
        measures = [bundled_measure(curve) for curve in bundled_site_curves(name)]
    else:
        own = _store_measure(store)
        measures = [own] if own is not None and own.kind in ("pga", "psa") else []
    return {measure.label: measure.period for measure in measures}


def _store_measure(store: Any) -> Measure | None:
    """The measure of the store's ``[intensity]`` (None without one)."""
    intensity = store.pound.intensity
    return intensity.measure if intensity is not None else None


def measure_choice(store: Any, hazard: str | None = None) -> pd.DataFrame:
    """Per configuration, β of ln(peak closure) given each measure the site's hazard has, the most efficient of them, and the
    most efficient of all candidates with its β.

    Parameters
    ----------
    store : xarray.Dataset
        A store with contact-free runs (stripes or IDA).
    hazard : str, optional
        A bundled curve naming the site (default: the store's ``[hazard] bundled``).

    Returns
    -------
    pandas.DataFrame
        One row per configuration (its labels as columns, ``where`` in
        words), a column per hazard measure (β), ``most efficient`` (among
        them; "" when the hazard has none), ``best candidate`` and ``best β``
        ("" and NaN, and ``most efficient`` "", when a stripe ran one motion).
        Its ``attrs``: ``hazard_measures`` (those columns' names),
        ``store_measure`` (the store's own measure, named alike: :attr:`stochpound.motions.Measure.label`; "" for none)
        and ``unjudged`` (why no measure is named, :data:`ONE_MOTION`; "" when one is).
    """
    from stochpound.risk import candidate_name, contact_free_closure, measure_efficiency, stripe_motions

    structure = periods_of_interest(store.pound.grid)
    available = hazard_measures(store, hazard)
    candidates = {**structure, **{f"hazard {name}": period for name, period in available.items() if period is not None}}
    beta = measure_efficiency(store, candidates, structure, studied=store.pound.definition.studied)["beta"].sel(response="closure")
    names = {name: candidate_name(period, f"hazard {name}") for name, period in available.items()}
    configurations = [d for d in beta.dims if d != "measure"]
    judged = stripe_motions(store, contact_free_closure(store)) > 1
    rows = []
    for index in np.ndindex(*[beta.sizes[d] for d in configurations]):
        cell = beta.isel(dict(zip(configurations, index)))
        row: dict[str, Label] = {d: cell[d].item() for d in configurations}
        row["where"] = ", ".join(f"{d}={cell[d].item()}" for d in configurations) or "all runs"
        hazard_betas = {label: float(cell.sel(measure=name)) for label, name in names.items()}
        row.update(hazard_betas)
        row["most efficient"] = min(hazard_betas, key=lambda label: np.nan_to_num(hazard_betas[label], nan=np.inf)) if hazard_betas and judged else ""
        own = cell.sel(measure=[m for m in cell["measure"].values if _of_configuration(str(m), structure, cell)])
        best = int(np.argmin(np.nan_to_num(own.values, nan=np.inf)))
        row["best candidate"], row["best β"] = (str(own["measure"].values[best]), float(own.values[best])) if judged else ("", np.nan)
        rows.append(row)
    frame = pd.DataFrame(rows)
    frame.attrs["hazard_measures"] = list(available)
    own = _store_measure(store)
    frame.attrs["store_measure"] = own.label if own is not None else ""
    frame.attrs["unjudged"] = "" if judged else ONE_MOTION
    return frame


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
