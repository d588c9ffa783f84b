"""Experiments: grids and ensembles of scenes run on dask into a crash-safe store.

>>> from stochpound import experiment                               # doctest: +SKIP
>>> exp = experiment.load_experiment("experiments/quickstart.toml")  # doctest: +SKIP
>>> report = experiment.run_experiment(exp, workers=2)               # doctest: +SKIP
>>> ds = experiment.open_store(report.store)                         # doctest: +SKIP

File format, store layout, resumption and clusters: ``docs/experiments.md``.
"""

from stochpound._errors import ExperimentError
from stochpound.store import (
    FIXED_BASE,
    Definition,
    GapAxis,
    MotionSource,
    MuAxis,
    Output,
    Solver,
    VariantAxis,
    is_fixed_base,
    is_gap_axis,
    open_store,
    read_definition,
)
from stochpound.experiment._experiment import Experiment
from stochpound.store import Case, Dim
from stochpound.experiment._runner import RunReport, default_store, load_experiment, run_experiment, seed_store
from stochpound.experiment._status import StatusReport, store_status
from stochpound.experiment._rare_event_run import RareEventReport, rare_event_sampler, run_rare_event
from stochpound.experiment._rare_event_check import crude_check
from stochpound.experiment._rare_event_store import RareEventResults, is_rare_event_store, open_rare_event_store, rare_event_results
from stochpound.experiment._rare_event_table import RareEventDefinition, RareEventTable, is_rare_event_file, load_rare_event, parse_rare_event

# For the other packages of stochpound (their interface to this one, not public API: not in __all__).
from stochpound.experiment._design_table import parse_design  # noqa: F401
from stochpound.experiment._ensemble import simulate_ensemble  # noqa: F401
from stochpound.experiment._estimate import LARGE_RUN_BYTES, LARGE_RUN_CASES  # noqa: F401
from stochpound.store import CASE  # noqa: F401
from stochpound.experiment._measure_choice import hazard_measures, measure_choice  # noqa: F401
from stochpound.experiment._parts import parts_folder, read_experiment_json  # noqa: F401
from stochpound.experiment._site import periods_of_interest  # noqa: F401
from stochpound.experiment._stripe_pools import TILT_PILOT, Tilt, scenario_table, table_chunks, table_scenario, tilted_seed  # noqa: F401
from stochpound.experiment._sources import resolve_motions  # noqa: F401
from stochpound.experiment._file_assembly import PartsIndex  # noqa: F401
from stochpound.experiment._rare_event_table import CLOSURES  # noqa: F401

__all__ = [
    "RareEventDefinition",
    "RareEventReport",
    "RareEventResults",
    "RareEventTable",
    "crude_check",
    "is_rare_event_file",
    "is_rare_event_store",
    "load_rare_event",
    "open_rare_event_store",
    "parse_rare_event",
    "rare_event_results",
    "rare_event_sampler",
    "run_rare_event",
    "FIXED_BASE",
    "Case",
    "Definition",
    "Dim",
    "Experiment",
    "ExperimentError",
    "GapAxis",
    "MotionSource",
    "MuAxis",
    "Output",
    "RunReport",
    "Solver",
    "StatusReport",
    "VariantAxis",
    "default_store",
    "seed_store",
    "is_fixed_base",
    "is_gap_axis",
    "load_experiment",
    "open_store",
    "read_definition",
    "run_experiment",
    "store_status",
]
