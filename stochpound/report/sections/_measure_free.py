"""The section of the answer without an intensity measure (formats :class:`stochpound.analysis.StoreMeasureFree`; docs/measure-free.md)."""

from __future__ import annotations

from stochpound.analysis import StoreMeasureFree
from stochpound.report.render import Paragraph, Section, Table


def measure_free_section(name: str, answer: StoreMeasureFree, hazard: str) -> Section:
    """The levels of every demand at the targets for each configuration of experiment ``name`` at a site of ruptures, with no
    intensity measure; ``hazard`` names the site of the conditioned answers (the Risk section's)."""
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
    return section
