"""The section of the answer without an intensity measure (formats :class:`stochpound.analysis.StoreMeasureFree`; docs/measure-free.md)."""

from __future__ import annotations

from stochpound.analysis import StoreMeasureFree, StoreSufficiency
from stochpound.report.render import Paragraph, Section, Table


def measure_free_section(name: str, answer: StoreMeasureFree, hazard: str, sufficiency: StoreSufficiency | None = None,
                         untested: str = "") -> Section:
    """The levels of every demand at the targets for each configuration of experiment ``name`` at a site of ruptures, with no
    intensity measure; ``hazard`` names the site of the conditioned answers (the Risk section's). ``sufficiency``: the test of the
    store's measure (:func:`stochpound.analysis.store_sufficiency`), its verdict per configuration in words and its table;
    ``untested``: why there is none (said as it is)."""
    section = Section(f"Without an intensity measure: experiment {name}", key=f"measure-free-{name}")
    section.add(Paragraph(
        f"The answer to the Risk section's question with no intensity measure at all, at the site of ruptures {answer.site}. Each "
        f"configuration's contact-free scene (the one its conditioned answer ran) is run under simulated motions of each rupture, "
        "and the rate at which a demand D exceeds x is λ(D > x) = Σ_r ν_r P(D > x | r), P the fraction of rupture r's runs beyond x "
        "(ν_r its annual rate): no measure, no scaling, no fragility and no hazard curve. For the closure, by the gap identity, this "
        "is the pounding rate of every gap, and its level at a target is the risk-targeted separation g*. "
        f"Conditions: {answer.conditions()}."
    ))
    section.add(Paragraph(
        f"The Risk section's answers are conditioned on the hazard of its site ({hazard}); this one belongs to the site of "
        "ruptures above. The two are answers for the same earthquakes only where that hazard is the one of these ruptures "
        "(an experiment's [hazard] ruptures); otherwise they are answers for two sites, and their difference is no test of the chain."
    ))
    section.add(Table(
        key=f"table-measure-free-{name}",
        caption=(f"Experiment {name}: the level of each demand exceeded at each target rate without an intensity measure (m; the "
                 f"closure's is g*), with its interval, at {answer.site_name}"),
        frame=answer.display_frame(),
        note=("closure: the largest over the contacts of a contact-free run; base displacement: the sliding base's largest; storey "
              "drift: the building's largest over its storeys (m, not a ratio). Every demand is read from the same runs; the runs "
              "after the first stage went where the closure's level of the rarest target needed them, so the other demands' "
              "intervals are wider where those runs serve them less."),
    ))
    if sufficiency is not None:
        _add_sufficiency(section, name, sufficiency)
    elif untested:
        section.add(Paragraph(f"The sufficiency of the store's measure was not tested: {untested}."))
    return section


def _add_sufficiency(section: Section, name: str, sufficiency: StoreSufficiency) -> None:
    """The sufficiency test of the store's measure: each configuration's verdict, from the data, and the slopes."""
    section.add(Paragraph(
        f"Is {sufficiency.measure} sufficient for the contact-free closure? Within each stripe every motion is at the same "
        f"{sufficiency.measure}, so a sufficient measure leaves no trend of ln closure with the motion's magnitude M, the ln of its "
        "rupture distance R or its ε (its own measure's standard deviates in its own earthquake); the slopes are fitted over the "
        f"stripes with one intercept a stripe. {sufficiency.verdict()}. Conditions: {sufficiency.results[0].conditions()}. A measure that "
        "passes may still miss the answer without a measure (through the selection, the fit or the motions); one that fails "
        "carries the trend into its g* wherever the stripes' earthquakes differ from the site's."
    ))
    section.add(Table(
        key=f"table-sufficiency-{name}",
        caption=f"Experiment {name}: the trend of ln closure with M, ln R and ε within the stripes of {sufficiency.measure}",
        frame=sufficiency.display_frame(),
        note="slope: ln closure per unit of the covariate; lower, upper: its interval; significant: p-value below the test's level.",
    ))
