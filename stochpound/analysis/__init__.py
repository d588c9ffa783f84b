"""Statistics of simulated responses, dask-friendly (lazy on chunked data).

Every function takes and returns xarray objects and reduces only the
dimensions it is told to, so it applies equally to one run (reduce over
``time``), to an experiment store (the grid's dimensions are carried along)
and to ensembles (reduce over ``realization``). Each statistic has one
implementation, a numpy kernel of :mod:`stochpound.stats.kernels`, which
these functions apply with :func:`xarray.apply_ufunc`.

This namespace also gives the site's hazard (:class:`HazardCurve`, the
hazard files and the stripes' consistency, of :mod:`stochpound.hazard`),
the code separation rules of a run (of :mod:`stochpound.codes`) and the two
names of the risk chain (:mod:`stochpound.risk`) the project's contract lists
here, :func:`fit_fragility` and :func:`mean_annual_frequency`. Small exceedance probabilities of
a run's response come from subset simulation (:func:`subset_simulation`,
which runs the solvers), or from importance sampling with a linear surrogate's
elementary events (:func:`linear_importance_sampling`). The statistics sit above all
three: none of them imports this package.
"""

from stochpound.analysis._moments import moments
from stochpound.stats import correlation
from stochpound.analysis._ensemble_statistics import ensemble_statistics
from stochpound.analysis._histogram import normal_histogram
from stochpound.analysis._impacts import impact_statistics
from stochpound.analysis._intervals import mean_interval, of_first, quantiles, running_mean, running_pounding_probability
from stochpound.analysis.mechanisms import amplification, ratcheting
from stochpound.analysis._peaks import peak_response
from stochpound.analysis._pounding import pounding_probability
from stochpound.analysis._separation import pounding_curve, required_separation, rule_exceedance
from stochpound.codes import contact_demands, fixed_base_cqc, separation_rules, store_contact_demands
from stochpound.analysis._subset_simulation import RESPONSES, subset_simulation
from stochpound.analysis._linear_importance import linear_importance_sampling, oscillator_rows, surrogate_level, uncovered_share
from stochpound.analysis._measure_free import (MEASURE_FREE_RESPONSES, MeasureFreeDemand, measure_free_demands, measure_free_risk,
                                               rate_weighted_levels)
from stochpound.analysis._measure_free_store import MEASURE_FREE_RUNS, StoreMeasureFree, scene_demands, store_measure_free
from stochpound.analysis._measure_comparison import compare_measures
from stochpound.analysis._sufficiency import SUFFICIENCY_LEVEL, StoreSufficiency, Sufficiency, store_sufficiency, stripe_regression
from stochpound.analysis._summary import run_summary
from stochpound.analysis._mechanism_cells import MechanismCells, WallPenetration
from stochpound.analysis._scenario_intensity import MeasureIntensity, ScenarioIntensity
from stochpound.analysis._store_ensemble import RARE, ProbabilityAt, StoreEnsemble
from stochpound.analysis._record_cases import RecordPounding
from stochpound.analysis._cell_statistics import CellStatistics
from stochpound.analysis._store_scenes import Configuration, StoreScenes
from stochpound.analysis._solver_checks import (
    COLLISION_VELOCITY,
    CROSS_CHECK_TOLERANCE,
    HARMONIC_AMPLITUDE,
    HARMONIC_DETUNING,
    REFERENCE_RTOL,
    SUMMARY_RTOL,
    CollisionCheck,
    HarmonicComparison,
    ModalCheck,
    ReferenceRun,
    free_collision_restitution,
)
from stochpound.analysis._store_separation import CONTACTS, WALLS, Closure, Needed, StoreSeparation, ValueRange
from stochpound.hazard import (
    RUPTURE_COLUMNS,
    HazardCurve,
    HazardFile,
    RuptureSite,
    StatedMeasure,
    bundled_rupture_sites,
    bundled_curves,
    bundled_measure,
    bundled_site_curves,
    hazard_consistency,
    probability_from_rate,
    rate_from_probability,
    read_hazard_file,
    return_period,
    scenario_hazard,
    stripe_rate_weights,
)

# For the other packages of stochpound (their interface to this one, not public API: not in __all__).
from stochpound.analysis._impacts import TABLE_COLUMNS  # noqa: F401
from stochpound.analysis._intervals import MIN_RUNS  # noqa: F401
from stochpound.analysis._summary import response_moments, top_floor_total_displacement  # noqa: F401
from stochpound.analysis._subset_simulation import (  # noqa: F401
    INITIAL_SCALE, PROPOSALS, ChainRun, SubsetLevel, SubsetSampler, curve_dataset, curve_thresholds, exceedance, exceedance_quantiles, level_attributes,
    level_probability, scene_response, warn_uncertified,
)
from stochpound.analysis._cell_statistics import ForceSpread, Largest  # noqa: F401
from stochpound.analysis._cells import CellLabels  # noqa: F401


CONTRACT_RISK_NAMES = ("fit_fragility", "mean_annual_frequency")
"""The risk chain's names the project's contract lists under this namespace (with :class:`HazardCurve` and
:func:`subset_simulation`, imported above): kept here as aliases of :mod:`stochpound.risk`'s (their canonical home), resolved
when first used, so that importing the statistics does not import the risk chain. The other risk names this namespace once
gave are retired (import them from :mod:`stochpound.risk`)."""


def __getattr__(name: str) -> object:
    """A contract name of the risk chain (:data:`CONTRACT_RISK_NAMES`), from :mod:`stochpound.risk` (imported on first use)."""
    if name in CONTRACT_RISK_NAMES:
        import stochpound.risk

        return getattr(stochpound.risk, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "moments",
    "correlation",
    "ensemble_statistics",
    "normal_histogram",
    "impact_statistics",
    "mean_interval",
    "of_first",
    "quantiles",
    "running_mean",
    "running_pounding_probability",
    "ratcheting",
    "amplification",
    "peak_response",
    "pounding_probability",
    "pounding_curve",
    "required_separation",
    "rule_exceedance",
    "contact_demands",
    "separation_rules",
    "store_contact_demands",
    "fixed_base_cqc",
    "run_summary",
    "StoreEnsemble",
    "ProbabilityAt",
    "RecordPounding",
    "CellStatistics",
    "StoreScenes",
    "Configuration",
    "CollisionCheck",
    "HarmonicComparison",
    "ModalCheck",
    "ReferenceRun",
    "free_collision_restitution",
    "COLLISION_VELOCITY",
    "CROSS_CHECK_TOLERANCE",
    "HARMONIC_AMPLITUDE",
    "HARMONIC_DETUNING",
    "REFERENCE_RTOL",
    "SUMMARY_RTOL",
    "RARE",
    "StoreSeparation",
    "Needed",
    "Closure",
    "CONTACTS",
    "WALLS",
    "ValueRange",
    "MechanismCells",
    "MeasureIntensity",
    "ScenarioIntensity",
    "WallPenetration",
    "subset_simulation",
    "linear_importance_sampling",
    "oscillator_rows",
    "surrogate_level",
    "uncovered_share",
    "RESPONSES",
    "measure_free_risk",
    "measure_free_demands",
    "rate_weighted_levels",
    "MeasureFreeDemand",
    "store_measure_free",
    "StoreMeasureFree",
    "scene_demands",
    "MEASURE_FREE_RUNS",
    "compare_measures",
    "stripe_regression",
    "Sufficiency",
    "store_sufficiency",
    "StoreSufficiency",
    "SUFFICIENCY_LEVEL",
    "MEASURE_FREE_RESPONSES",
    "HazardCurve",
    "HazardFile",
    "StatedMeasure",
    "read_hazard_file",
    "bundled_curves",
    "bundled_measure",
    "bundled_site_curves",
    "probability_from_rate",
    "rate_from_probability",
    "return_period",
    "hazard_consistency",
    "stripe_rate_weights",
    "scenario_hazard",
    "RUPTURE_COLUMNS",
    "RuptureSite",
    "bundled_rupture_sites",
    *CONTRACT_RISK_NAMES,
]
