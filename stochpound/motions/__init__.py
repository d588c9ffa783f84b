"""Synthetic ground motions: white noise, Kanai–Tajimi and Clough–Penzien PSDs, envelopes, generators.

>>> from stochpound import motions
>>> a = motions.kanai_tajimi(100, 20.0, 0.01, omega_g=15.0, zeta_g=0.6, pga=3.0,
...                          envelope="jennings", seed=1)          # doctest: +SKIP
>>> a.sizes                                                         # doctest: +SKIP
{'realization': 100, 'time': 2001}

Every synthetic motion is a function of a vector of standard normals
(:func:`normal_motion`, :class:`NormalMotion`), for samplers that move in
that space (subset simulation).

Intensity measures and the response spectrum (exact for accelerations linear
between samples): :func:`intensity_measures`, :func:`response_spectrum`.

An earthquake scenario at a site as one value: :class:`Scenario`. The
conditional spectrum of a site scenario (NGA-West2 models, Baker–Jayaram
correlation): :func:`conditional_spectrum`, and the scenario's own median and σ
of a measure: :func:`scenario_distribution` (a scenario's rupture geometry and
basin depths, :data:`GEOMETRY_FIELDS`, given or estimated); records chosen and scaled to it
(Jayaram, Lin & Baker 2011): :func:`selection_pool`, :func:`selection_periods`,
:func:`select_motions`; the scenario of every level fitted to the site's own
hazard curves where no disaggregation is at hand: :func:`fit_scenarios`,
:func:`fit_levels`, :func:`recomputed_hazard`.

Site-based stochastic motions of a scenario (Rezaeian & Der Kiureghian 2010,
calibrated to the NGA-West2 models): :func:`site_motions`, the same map
from explicit standard normals: :func:`site_motions_from_normals`, and the
same motions as a synthetic ensemble (``type = "scenario_motions"``):
:func:`scenario_motions`, :class:`ScenarioNormalMotion`.

Conventions (PSD two-sided in ω, σ² = ∫ S dω; SI units) are in ``docs/motions.md``.
"""

from stochpound.motions._conditional import TRUNCATION_EPSILON, conditional_spectrum, scenario_distribution
from stochpound.motions._scenario import GEOMETRY_FIELDS, Scenario
from stochpound.motions._fitted import fit_levels, fit_scenarios, recomputed_hazard
from stochpound.motions.baseline import baseline_correct, final_velocity_displacement
from stochpound.motions.envelopes import (
    ENVELOPES,
    AminAng,
    CallableEnvelope,
    Envelope,
    Jennings,
    SaragoniHart,
    Trapezoidal,
    make_envelope,
)
from stochpound.motions.generators import filter_from_normals, filter_samples, spectral_from_phases, spectral_samples, stationary_samples
from stochpound.motions._measures import intensity_measures, peak_ground_motion, sa_avg, significant_duration
from stochpound.motions.intensity import poisson_peak_factor, s0_from_pga, s0_from_rms, simulated_peak_factor
from stochpound.motions._presets import SOIL_PRESETS, SoilPreset, soil_preset
from stochpound.motions.psd import (
    FilteredWhiteNoise,
    clough_penzien_model,
    clough_penzien_psd,
    high_pass_gain,
    kanai_tajimi_model,
    kanai_tajimi_psd,
    kanai_tajimi_variance,
)
from stochpound.motions._site_motions import site_model_provenance, site_motions, site_motions_from_normals
from stochpound.motions._selection import TARGET_TOLERANCE, misses_target, select_motions, selection_periods, selection_pool
from stochpound.motions._seeding import realization_rng, realization_rngs
from stochpound.motions._spectrum import response_spectrum
from stochpound.motions._normals import NormalMotion
from stochpound.motions._scenario_motions import ScenarioNormalMotion, scenario_motions
from stochpound.motions._synthetic import (
    PSD_CONVENTION,
    SYNTHETIC_TYPES,
    clough_penzien,
    kanai_tajimi,
    normal_motion,
    synthetic_ground_motion,
    white_noise,
)

# For the other packages of stochpound (their interface to this one, not public API: not in __all__).
from stochpound.motions._arias import DEFAULT_G, arias_intensity  # noqa: F401
from stochpound.motions._conditional import CONDITIONING_MEASURES, MODEL_DAMPING, PERIOD_RANGE  # noqa: F401
from stochpound.motions._conditional import (  # noqa: F401
    check_damping,
    conditional_distribution,
    conditioning_attrs,
    conditioning_measure,
    measure_distribution,
    scenario_spectrum,
    spectrum_dataset,
)
from stochpound.motions._measure import KINDS as MEASURE_KINDS, Measure
from stochpound.motions._scenario import MECHANISMS, given_scenario  # noqa: F401
from stochpound.motions._selection import array_pool, pool_intensity  # noqa: F401  (the experiment's pool of simulated motions)
from stochpound.motions._spectrum import pseudo_spectra  # noqa: F401
from stochpound.motions._site_calibration import calibration_table, fit_calibration  # noqa: F401
from stochpound.motions._site_motions import parameter_normals  # noqa: F401  (the experiment's pool tilted to each stripe)
from stochpound.motions._site_motions import SITE_MOTION_LIMITS  # noqa: F401  (the analysis's measure-free risk clamps to it)
from stochpound.motions._site_motions import stated_calibration  # noqa: F401  (scene files, ensembles and stripe pools refuse another calibration)

__all__ = [
    "ENVELOPES",
    "MEASURE_KINDS",
    "Measure",
    "GEOMETRY_FIELDS",
    "Scenario",
    "PSD_CONVENTION",
    "TARGET_TOLERANCE",
    "TRUNCATION_EPSILON",
    "SOIL_PRESETS",
    "SYNTHETIC_TYPES",
    "AminAng",
    "CallableEnvelope",
    "Envelope",
    "FilteredWhiteNoise",
    "Jennings",
    "NormalMotion",
    "SaragoniHart",
    "ScenarioNormalMotion",
    "SoilPreset",
    "Trapezoidal",
    "baseline_correct",
    "clough_penzien",
    "clough_penzien_model",
    "clough_penzien_psd",
    "conditional_spectrum",
    "filter_from_normals",
    "filter_samples",
    "fit_levels",
    "fit_scenarios",
    "final_velocity_displacement",
    "high_pass_gain",
    "intensity_measures",
    "kanai_tajimi",
    "kanai_tajimi_model",
    "kanai_tajimi_psd",
    "kanai_tajimi_variance",
    "make_envelope",
    "misses_target",
    "normal_motion",
    "peak_ground_motion",
    "poisson_peak_factor",
    "realization_rng",
    "realization_rngs",
    "recomputed_hazard",
    "response_spectrum",
    "s0_from_pga",
    "s0_from_rms",
    "sa_avg",
    "scenario_distribution",
    "scenario_motions",
    "select_motions",
    "selection_periods",
    "selection_pool",
    "significant_duration",
    "soil_preset",
    "simulated_peak_factor",
    "spectral_from_phases",
    "site_model_provenance",
    "site_motions",
    "site_motions_from_normals",
    "spectral_samples",
    "stationary_samples",
    "synthetic_ground_motion",
    "white_noise",
]
