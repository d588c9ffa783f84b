"""Pounding risk at a site: fragility, hazard, mean annual frequency, the risk-targeted separation g* and the code rules.

The chain (docs/risk.md): the pounding fragility of every gap from
intensity stripes or IDA runs (:func:`fit_fragility`,
:func:`stripe_fragility`, :func:`ida_fragility`), integrated with the
site's hazard curve (:class:`HazardCurve`) into the mean annual frequency
of pounding (:func:`mean_annual_frequency`, :func:`risk_curve`), the gap
that meets a target probability (:func:`risk_targeted_separation`), and
the code separation rules in risk terms (:func:`code_rules_risk`), and the
separations as the codes compute them from a design analysis
(:func:`asce7_inelastic_displacement`, :func:`ec8_design_displacement`,
:func:`srss_separation`, :func:`asce7_isolator_displacement`; an isolated
building's ASCE 7 chapter 17 design at both friction bounds,
:func:`chapter17_design`, and its separation from a fixed-base neighbour,
:func:`isolated_separation`), applied to
a store's scene and ``[design]`` with their risk (:func:`design_separations`,
:func:`design_rules_risk`). For an
experiment store, :func:`read_risk_inputs` reads once what the chain needs
(:class:`RiskInputs`) and :func:`store_risk` runs the whole chain on them and returns a
:class:`StoreRisk`, whose tables (:meth:`StoreRisk.to_frame`,
:meth:`StoreRisk.separation_frame`, :meth:`StoreRisk.rules_frame`) the
report renders and ``stochpound risk`` prints; :func:`stripe_demand_rate`
the same rate curve from a lognormal demand per stripe (every run's value,
not only the counts; :func:`stripe_demand_moments` its parameters per stripe); :func:`store_demands` gives
the demand hazard curves and the moat walls' limit state
(:class:`StoreDemands`); :func:`limit_state_risk` the fragility and MAF of
limit states beyond first contact (:class:`LimitState`: drift ratios,
ductility, floor acceleration, impact force, a sliding base's displacement) at every gap
of a store's grid against its contact-free twins (:func:`gap_cost_frame`), what governs
each configuration against the limit states' objectives in each treatment of the runs beyond the model
(:func:`governing_limit_state`, :func:`objectives_frame`);
:func:`store_damage` the ductility and residual drift demands of yielding
buildings per stripe, the runs beyond the model and the governing limit
state, each limit state against its own objective (:class:`StoreDamage`);
:func:`collapse_risk` g* with the runs beyond the model counted apart as
collapses, as FEMA P-58 does (:class:`CollapseRisk`); :func:`rate_collapses_apart` the same for
any demand (the demand curves' and the limit states' λ both ways).

This package is the canonical home of these names; the ones that
:mod:`stochpound.analysis` exported before it existed stay importable from
there as aliases.
"""

from stochpound.hazard import HazardCurve, bundled_curves, probability_from_rate, rate_from_probability, return_period
from stochpound.risk._fragility import Fragility, fit_fragility
from stochpound.risk._fragility_ensemble import (
    BOOTSTRAP,
    fragility_band,
    fragility_surface,
    homogeneous_capacities,
    ida_fragility,
    limit_state_events,
    stripe_fragility,
)
from stochpound.risk._maf import TARGETS, degenerate_text, demand_hazard_curve, flat_fit_maf, mean_annual_frequency, rate_intervals, risk_curve, risk_targeted_separation
from stochpound.risk._code_rules import code_rules_risk
from stochpound.codes import Chapter17Design, IsolatedPlan, IsolatedSeparation, IsolationBound, MceSpectrum, SlidingBase, chapter17_design, isolated_separation
from stochpound.risk._code_gaps import (
    Asce7Design,
    Ec8Design,
    asce7_inelastic_displacement,
    asce7_isolator_displacement,
    ec8_design_displacement,
    modal_floor_displacements,
    srss_separation,
)
from stochpound.risk._design_rules import DESIGN_RULE_LEVELS, design_rules_risk, design_separations
from stochpound.risk._site_spectrum import site_mce
from stochpound.risk._inputs import (RiskInputError, RiskInputs, contact_free_closure, has_risk, read_risk_inputs, selection_misses, site_hazard,
                                    stripes_beyond_truncation, unreachable_targets)
from stochpound.risk._inputs import configuration_scene
from stochpound.risk._inputs import stripe_motions  # noqa: F401  (for stochpound.experiment.measure_choice: not public API)
from stochpound.risk._chain import StoreRisk, pounding_fragility, risk_gaps, store_risk
from stochpound.risk._gap_grid import GRID_TOLERANCE
from stochpound.risk._limit_states import POUNDING as POUNDING_AT_G_STAR  # noqa: F401  (for the report's sections: not public API)
from stochpound.risk._demands import StoreDemands, store_demands
from stochpound.risk._limit_states import (KINDS as LIMIT_STATE_KINDS, LimitState, disagreement_text, gap_cost_frame, governing_limit_state,
                                           judged_ratio, limit_state_bounds, limit_state_fits, limit_state_pinned, limit_state_problem,
                                           limit_state_risk, limit_states_from_table, objectives_frame, undecided)
from stochpound.risk._efficiency import measure_efficiency, most_efficient
from stochpound.risk._efficiency import candidate_name  # noqa: F401  (for stochpound.experiment.measure_choice: not public API)
from stochpound.risk._collapse import CollapseRisk, beyond_model, collapse_risk, collapsed_runs, rate_collapses_apart
from stochpound.risk._sensitivity import ALTERNATIVES, MODELLING_DISPERSIONS, Sensitivity, check_alternative, separation_sensitivity, sensitivity_text
from stochpound.risk._damage import DAMAGE_DEMANDS, DEFAULT_LIMIT_STATES, DEFAULT_SOURCE as DEFAULT_LIMIT_STATES_SOURCE, MODEL_DRIFT_LIMIT, StoreDamage, store_damage
from stochpound.hazard import hazard_consistency, read_hazard_file, stripe_rate_weights
from stochpound.risk._site_consistency import consistency_at_targets, site_consistency
from stochpound.risk._stripe_demand import stripe_demand_moments, stripe_demand_rate
from stochpound.risk._stripe_coverage import (UNIDENTIFIED_BETA, at_lowest_stripe, fragility_at_separation, maf_outside_stripes, stripes_only_maf, stripes_upper_maf,
                                              unidentified)

__all__ = [
    "Fragility",
    "fit_fragility",
    "fragility_band",
    "fragility_surface",
    "homogeneous_capacities",
    "ida_fragility",
    "limit_state_events",
    "stripe_fragility",
    "HazardCurve",
    "bundled_curves",
    "read_hazard_file",
    "probability_from_rate",
    "rate_from_probability",
    "return_period",
    "demand_hazard_curve",
    "stripe_demand_moments",
    "stripe_demand_rate",
    "maf_outside_stripes",
    "fragility_at_separation",
    "mean_annual_frequency",
    "flat_fit_maf",
    "risk_curve",
    "rate_intervals",
    "degenerate_text",
    "risk_targeted_separation",
    "code_rules_risk",
    "Asce7Design",
    "Ec8Design",
    "modal_floor_displacements",
    "asce7_inelastic_displacement",
    "ec8_design_displacement",
    "srss_separation",
    "asce7_isolator_displacement",
    "chapter17_design",
    "Chapter17Design",
    "IsolationBound",
    "SlidingBase",
    "MceSpectrum",
    "IsolatedPlan",
    "isolated_separation",
    "IsolatedSeparation",
    "design_separations",
    "design_rules_risk",
    "DESIGN_RULE_LEVELS",
    "site_mce",
    "contact_free_closure",
    "configuration_scene",
    "pounding_fragility",
    "risk_gaps",
    "store_risk",
    "StoreRisk",
    "read_risk_inputs",
    "RiskInputs",
    "store_demands",
    "StoreDemands",
    "LimitState",
    "LIMIT_STATE_KINDS",
    "limit_states_from_table",
    "limit_state_problem",
    "limit_state_risk",
    "gap_cost_frame",
    "governing_limit_state",
    "objectives_frame",
    "disagreement_text",
    "limit_state_fits",
    "judged_ratio",
    "limit_state_bounds",
    "limit_state_pinned",
    "undecided",
    "store_damage",
    "DAMAGE_DEMANDS",
    "StoreDamage",
    "DEFAULT_LIMIT_STATES",
    "DEFAULT_LIMIT_STATES_SOURCE",
    "MODEL_DRIFT_LIMIT",
    "CollapseRisk",
    "collapse_risk",
    "collapsed_runs",
    "beyond_model",
    "rate_collapses_apart",
    "at_lowest_stripe",
    "stripes_only_maf",
    "stripes_upper_maf",
    "unidentified",
    "UNIDENTIFIED_BETA",
    "separation_sensitivity",
    "sensitivity_text",
    "Sensitivity",
    "MODELLING_DISPERSIONS",
    "ALTERNATIVES",
    "check_alternative",
    "GRID_TOLERANCE",
    "hazard_consistency",
    "consistency_at_targets",
    "site_consistency",
    "measure_efficiency",
    "most_efficient",
    "has_risk",
    "selection_misses",
    "unreachable_targets",
    "stripes_beyond_truncation",
    "site_hazard",
    "stripe_rate_weights",
    "RiskInputError",
    "TARGETS",
    "BOOTSTRAP",
]
