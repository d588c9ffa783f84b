"""The lines of ``stochpound risk`` naming the most efficient intensity measure (:func:`stochpound.experiment.measure_choice`)."""

from __future__ import annotations

from typing import Any


def efficient_measure_lines(store: Any, hazard: str | None) -> list[str]:
    """Lines naming, per configuration, the measure of least β of ln(closure) among those the site's hazard has, and among all candidates."""
    from stochpound.experiment import measure_choice

    frame = measure_choice(store, hazard)
    if frame.attrs["unjudged"]:
        return ["", f"Which measure: {frame.attrs['unjudged']}."]
    lines = ["", "Which measure (β: dispersion of ln(peak closure) given the measure, over the contact-free runs; smaller needs fewer motions):"]
    for _, row in frame.iterrows():
        given = "; ".join(f"{label} {row[label]:.3f}" for label in frame.attrs["hazard_measures"])
        choice = f"most efficient the site's hazard has: {row['most efficient']} ({given})" if row["most efficient"] else "the site's hazard is in no candidate measure"
        lines.append(f"  {row['where']}: {choice}; of all candidates: {row['best candidate']} ({row['best β']:.3f})")
    return lines
