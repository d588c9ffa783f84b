"""The sections of the report of any experiment's stores, and what they read the stores with.

Its namespace gives what the report's assembly (``stochpound.report.assemble``)
and a study's package build with.
"""

from stochpound.report.sections._accuracy import harmonic_comparisons
from stochpound.report.sections._damage import damage_section
from stochpound.report.sections._description import StoreDefinition
from stochpound.report.sections._ensembles import INTERVAL_NOTE
from stochpound.report.sections._generic import store_section
from stochpound.report.sections._intensity import intensity_section
from stochpound.report.sections._rare_events import rare_event_section
from stochpound.report.sections._risk import risk_section
from stochpound.report.sections._laws import law_axis, laws_section
from stochpound.report.sections._methods import methods_section
from stochpound.analysis import WALLS
from stochpound.report.sections._measure_free import measure_free_section
from stochpound.report.sections._separation import separation_section
from stochpound.report.sections._store_reading import definition_source, open_stores, select, value
from stochpound.report.sections._summary import experiment_summary, move_per_cell_tables

__all__ = [
    "rare_event_section",
    "risk_section",
    "damage_section",
    "INTERVAL_NOTE",
    "WALLS",
    "StoreDefinition",
    "experiment_summary",
    "harmonic_comparisons",
    "intensity_section",
    "law_axis",
    "laws_section",
    "methods_section",
    "measure_free_section",
    "move_per_cell_tables",
    "open_stores",
    "definition_source",
    "select",
    "separation_section",
    "store_section",
    "value",
]
