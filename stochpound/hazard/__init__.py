"""A site's seismic hazard: the curve, the files it is read from, an experiment's ``[hazard]`` table, the stripes' consistency with it.

:class:`HazardCurve` is the mean annual rate at which an intensity measure
is exceeded (a table or a power law; the bundled sites' curves);
:func:`read_hazard_file` reads one from stochpound's, OpenQuake's or
nshmp-haz's files with what it is a curve of (a :class:`StatedMeasure`;
:func:`bundled_measure` gives a bundled curve's :class:`~stochpound.motions.Measure`); :func:`parse_hazard` reads
an experiment file's ``[hazard]`` table into the canonical entry a store
carries, :func:`stored_hazard` gives a store's curve back and
:func:`hazard_option` reads ``stochpound risk --hazard``;
:func:`site_curve` reads an entry of ``[site] curves`` (the curves a fitted scenario is fitted to);
:func:`hazard_consistency` recomputes the hazard at another measure from
the stripes' motions; :func:`scenario_hazard` is the hazard of a site
shaken by one earthquake scenario, consistent with the ground-motion models
by construction; a :class:`RuptureSite` is a site given by its ruptures
(a table of them, :func:`bundled_rupture_sites` the demonstration ones):
the hazard of any measure, its exact disaggregation, the uniform-hazard
spectrum and the exact conditional spectrum. The experiment reader, the statistics
(:mod:`stochpound.analysis`, which gives these names to its users) and the
risk chain (:mod:`stochpound.risk`) all read the hazard here: this package
imports none of them.
"""

from stochpound.hazard._curve import HazardCurve, bundled_curves, bundled_measure, bundled_site_curves, probability_from_rate, rate_from_probability, return_period
from stochpound.hazard._files import HazardFile, StatedMeasure, parse_units, read_hazard_file
from stochpound.hazard._consistency import hazard_consistency, stripe_rate_weights
from stochpound.hazard._ruptures import RUPTURE_COLUMNS, RuptureSite, bundled_rupture_sites
from stochpound.hazard._scenario import scenario_hazard
from stochpound.hazard._setting import check_covers, hazard_curve, hazard_option, parse_hazard, stored_hazard

# For the other packages of stochpound (their interface to this one, not public API: not in __all__).
from stochpound.hazard._ruptures import SITE_FIELDS as RUPTURE_SITE_FIELDS, named_rupture_site  # noqa: F401
from stochpound.hazard._site_curves import site_curve, site_curve_label  # noqa: F401

__all__ = [
    "HazardCurve",
    "bundled_curves",
    "bundled_measure",
    "bundled_site_curves",
    "probability_from_rate",
    "rate_from_probability",
    "return_period",
    "HazardFile",
    "StatedMeasure",
    "read_hazard_file",
    "parse_units",
    "hazard_consistency",
    "stripe_rate_weights",
    "scenario_hazard",
    "RUPTURE_COLUMNS",
    "RuptureSite",
    "bundled_rupture_sites",
    "parse_hazard",
    "hazard_curve",
    "check_covers",
    "hazard_option",
    "stored_hazard",
]
