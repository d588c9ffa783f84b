"""Statistics of simulated responses, dask-friendly (lazy on chunked data).

Every function takes and returns xarray objects and reduces only the
dimensions it is told to, so it applies equally to one run (reduce over
``time``), to an experiment store (the grid's dimensions are carried along)
and to ensembles (reduce over ``realization``). Each statistic has one
implementation, a numpy kernel of :mod:`stochpound.analysis.kernels`, which
these functions apply with :func:`xarray.apply_ufunc`.

The hazard curve (:class:`~stochpound.risk.HazardCurve`, which an
experiment's ``[hazard]`` table is read with) is defined here, below the
experiment layer; the risk chain built on these statistics is the package
:mod:`stochpound.risk`, whose names this namespace also gives, as aliases,
to code written before that package existed.
"""

from stochpound.analysis._moments import moments
from stochpound.analysis._correlation import correlation
from stochpound.analysis._ensemble_statistics import ensemble_statistics
from stochpound.analysis._histogram import normal_histogram
from stochpound.analysis._impacts import impact_statistics
from stochpound.analysis._intervals import mean_interval, of_first, quantiles, running_mean, running_pounding_probability
from stochpound.analysis.mechanisms import amplification, ratcheting
from stochpound.analysis._peaks import peak_response
from stochpound.analysis._pounding import pounding_probability
from stochpound.analysis._separation import pounding_curve, required_separation, rule_exceedance
from stochpound.analysis._separation_rules import contact_demands, fixed_base_cqc, separation_rules, store_contact_demands
from stochpound.analysis._summary import run_summary
from stochpound.analysis._consistency import hazard_consistency, stripe_rate_weights
from stochpound.analysis._hazard import HazardCurve, bundled_curves, bundled_measure, probability_from_rate, rate_from_probability, return_period
from stochpound.analysis._hazard_files import HazardFile, read_hazard_file


def __getattr__(name: str) -> object:
    """A risk chain's name, from :mod:`stochpound.risk` (imported on first use)."""
    if name in _ALIASES:
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
    "Fragility",
    "fit_fragility",
    "fragility_band",
    "fragility_surface",
    "homogeneous_capacities",
    "ida_fragility",
    "limit_state_events",
    "stripe_fragility",
    "HazardCurve",
    "HazardFile",
    "read_hazard_file",
    "bundled_curves",
    "bundled_measure",
    "probability_from_rate",
    "rate_from_probability",
    "return_period",
    "demand_hazard_curve",
    "mean_annual_frequency",
    "risk_curve",
    "risk_targeted_separation",
    "code_rules_risk",
    "contact_free_closure",
    "pounding_fragility",
    "hazard_consistency",
    "stripe_rate_weights",
    "risk_gaps",
    "store_risk",
    "StoreRisk",
]
_ALIASES = frozenset(__all__) - set(globals())
"""The names ``__all__`` gives that this module does not define: the risk chain's, which it exported before :mod:`stochpound.risk`
existed. They are aliases of that package's (the canonical names), resolved when first used, so that importing the statistics
does not import the risk chain (which sits above them)."""
