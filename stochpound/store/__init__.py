"""Experiment stores: what a store is and holds, read one way, below the analysis.

>>> ds = stochpound.open_store("quickstart.nc")      # doctest: +SKIP
>>> ds.pound.definition.gaps                        # doctest: +SKIP
>>> ds.pound.scene(gap=0.02, record="elcentro")     # doctest: +SKIP

The package holds the definition parsed into types
(:func:`read_definition`, :class:`Definition`, its identity
:func:`definition_sha256`), the catalogue of the store's variables
(:data:`CATALOGUE`: units and long name of each, declared once), the gap axes
and the selections by meaning (contact-free, wall-free, fixed-base cases), the
stripes' site scenario (:func:`scenario_kind`, :func:`scenario_ranges`),
what an experiment is (:class:`ExperimentGrid`: its dimensions, cases with
stable ids and each case's scene, edited by the scene edits of this layer),
:func:`open_store`, and the one door to an open store, the ``pound``
accessor of an xarray dataset (:class:`StoreAccessor`). It imports the model
and the shared utilities only: the experiment layer writes stores, the
analysis, the risk chain, the report and the command line read them through
here.
"""

from stochpound.store._accessor import ACCESSOR, StoreAccessor
from stochpound.store._catalogue import (
    CASE_SUMMARIES,
    CATALOGUE,
    IMPACT_TABLE,
    REFERENCE_HISTORY,
    REFERENCE_SUMMARIES,
    STOREY_SUMMARIES,
    LIMIT_STATE_DEMANDS,
    TIME_HISTORIES,
    WALL_SUMMARIES,
    StoreVariable,
)
from stochpound.model.friction import FIXED_BASE, is_fixed_base
from stochpound.store._definition import (
    NOT_IN_IDENTITY,
    Definition,
    GapAxis,
    Design,
    DesignEc8,
    DesignIsolation,
    Hazard,
    Intensity,
    LimitStateCapacities,
    LimitStates,
    MotionSource,
    MuAxis,
    Output,
    Solver,
    VariantAxis,
    canonical_json,
    definition_sha256,
    Site,
    read_definition,
    scene_g,
)
from stochpound.store._grid import Case, Dim, ExperimentGrid, Point
from stochpound.store._stripe_selection import Selection, SimulatedMotions
from stochpound.store._gap_axes import (
    SETS,
    contact_free,
    contact_gap_dims,
    gap_dims,
    has_contact_free,
    has_wall_free,
    is_gap_axis,
    wall_axis,
    wall_free,
    walls_only,
    wall_gap_dims,
    with_contacts,
    with_walls,
)
from stochpound.store._motion_table import MotionTable
from stochpound.store._open import open_store
from stochpound.store._provenance import Provenance, VariableAttributes
from stochpound.store._scenario import SCENARIO_KINDS, scenario_kind, scenario_ranges
from stochpound.store._selections import fixed_base, has_fixed_base_twins, isolated_mus, select_case

# For the other packages of stochpound (their interface to this one, not public API: not in __all__).
from stochpound.store._catalogue import CASE, KINDS, REFERENCE  # noqa: F401
from stochpound.store._definition import MEASURES  # noqa: F401
from stochpound.store._progress import UnfinishedStoreError, cases_done, check_finished  # noqa: F401
from stochpound.store._grid import CONDITIONAL_SPECTRUM, SIMULATED, SIMULATED_FIELD, Label  # noqa: F401
from stochpound.model.fields import TomlTable  # noqa: F401
from stochpound.store._scene_edits import apply_overrides, building_names, building_table, reference_scene, with_motion, with_open_gaps  # noqa: F401
from stochpound.store._stripe_motions import motion_earthquakes, motions_that_ran, ran_motions, simulated_that_ran, stripe_holdings  # noqa: F401

__all__ = [
    "ACCESSOR",
    "CASE_SUMMARIES",
    "CATALOGUE",
    "FIXED_BASE",
    "IMPACT_TABLE",
    "NOT_IN_IDENTITY",
    "REFERENCE_HISTORY",
    "REFERENCE_SUMMARIES",
    "SCENARIO_KINDS",
    "SETS",
    "STOREY_SUMMARIES",
    "LIMIT_STATE_DEMANDS",
    "TIME_HISTORIES",
    "WALL_SUMMARIES",
    "Case",
    "Definition",
    "Design",
    "DesignEc8",
    "DesignIsolation",
    "Dim",
    "ExperimentGrid",
    "GapAxis",
    "Hazard",
    "Intensity",
    "LimitStateCapacities",
    "LimitStates",
    "MotionSource",
    "MotionTable",
    "MuAxis",
    "Output",
    "Site",
    "Selection",
    "SimulatedMotions",
    "Point",
    "Provenance",
    "Solver",
    "StoreAccessor",
    "StoreVariable",
    "VariableAttributes",
    "VariantAxis",
    "canonical_json",
    "contact_free",
    "contact_gap_dims",
    "definition_sha256",
    "fixed_base",
    "gap_dims",
    "has_contact_free",
    "has_fixed_base_twins",
    "has_wall_free",
    "is_fixed_base",
    "is_gap_axis",
    "isolated_mus",
    "open_store",
    "read_definition",
    "scenario_kind",
    "scenario_ranges",
    "scene_g",
    "select_case",
    "wall_axis",
    "wall_free",
    "walls_only",
    "wall_gap_dims",
    "with_contacts",
    "with_walls",
]
