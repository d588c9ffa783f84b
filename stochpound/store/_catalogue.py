"""The catalogue of a store's result variables: name, dimensions, dtype, units, long name.

A store holds, on its grid, the summaries of every case and of every
fixed-base reference, the kept time histories, and the table of impacts.
Their metadata is declared here, once; the store's layout
(:mod:`stochpound.experiment._file_layout`) is built from it without running
anything. The tests hold the catalogue against what a real
:func:`stochpound.simulate` and the summaries of
:mod:`stochpound.experiment._summary` return, so it cannot drift from them.

``dims`` are the dimensions of one case's value (a history's ``time`` left
out): the grid's dimensions come before them in the store (the impact table
has none: its rows of every case form one dimension, ``impact``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

CASE = "case"
REFERENCE = "reference"
KINDS = (REFERENCE, CASE)
"""The kinds of case a store holds, in store order: the fixed-base references and the cases."""

_STUDIED = "of the studied building's top-floor total displacement"
_ALONE = " (studied building alone on a fixed base)"


@dataclass(frozen=True)
class StoreVariable:
    """One result variable of a store.

    Attributes
    ----------
    name : str
        The variable's name in the store (and in the run or summary it comes from).
    dims : tuple of str
        Dimensions of one case's value (``building``, ``floor``, ``contact``; a history's ``time`` left out;
        the impact table's ``impact``, its rows, which the store concatenates over the cases).
    dtype : str
        numpy dtype of the value as computed (``f8``, ``i8``, ``i1``, ``b1``); the store widens summaries (``i8``, ``f8``) and keeps histories as ``f8``.
    units : str
        CF units (``1``: dimensionless).
    long_name : str
        What it is, in words.
    """

    name: str
    dims: tuple[str, ...]
    dtype: str
    units: str
    long_name: str

    @property
    def attrs(self) -> dict[str, str]:
        """``units`` and ``long_name``, as stored."""
        return {"units": self.units, "long_name": self.long_name}


#: Summaries of every case, in store order (the demands only with ``[output] demands = true``).
CASE_SUMMARIES = (
    StoreVariable("impacts", (), "i8", "1", "number of impacts"),
    StoreVariable("impacts_in_phase", (), "i8", "1", "impacts with both floors moving the same way at onset"),
    StoreVariable("impacts_out_of_phase", (), "i8", "1", "impacts with the floors moving towards each other at onset"),
    StoreVariable("peak_impact_force", (), "f8", "N", "largest impact force"),
    StoreVariable("longest_impact", (), "f8", "s", "longest impact duration"),
    StoreVariable("total_impulse", (), "f8", "N s", "sum of impact impulses"),
    StoreVariable("response_mean", (), "f8", "m", f"mean {_STUDIED}"),
    StoreVariable("response_variance", (), "f8", "m2", f"variance (population) {_STUDIED}"),
    StoreVariable("response_std", (), "f8", "m", f"standard deviation (population) {_STUDIED}"),
    StoreVariable("response_skewness", (), "f8", "1", f"skewness m3/m2^1.5 {_STUDIED}"),
    StoreVariable("response_excess", (), "f8", "1", f"coefficient of excess (kurtosis - 3) {_STUDIED}"),
    StoreVariable("energy_residual_ratio", (), "f8", "1", "largest energy residual relative to the largest input energy"),
    StoreVariable("fixed_base_correlation", (), "f8", "1", f"correlation {_STUDIED} with the same building alone on a fixed base"),
    StoreVariable("peak_total_displacement", ("building",), "f8", "m", "peak |total displacement| over floors and time"),
    StoreVariable("peak_relative_displacement", ("building",), "f8", "m", "peak |displacement relative to the base| over floors and time"),
    StoreVariable("peak_sliding_displacement", ("building",), "f8", "m", "peak |sliding displacement|"),
    StoreVariable("residual_sliding", ("building",), "f8", "m", "sliding displacement at the end of the motion"),
    StoreVariable("events_total", (), "i8", "1", "events located by the solver"),
    StoreVariable("contact_peak_displacement_left", ("contact",), "f8", "m", "peak |y| of the contact's left floor (u1)"),
    StoreVariable("contact_peak_displacement_right", ("contact",), "f8", "m", "peak |y| of the contact's right floor (u2)"),
    StoreVariable("contact_correlation", ("contact",), "f8", "1", "correlation of the two floors' displacement histories (rho)"),
    StoreVariable("peak_contact_closure", ("contact",), "f8", "m", "largest closure over the run: the separation this run needed"),
    StoreVariable("peak_floor_acceleration", ("building",), "f8", "m s-2", "largest peak total (absolute) floor acceleration over the building's floors"),
    StoreVariable("peak_interstorey_drift", ("building",), "f8", "m", "largest peak storey drift over the building's storeys"),
    StoreVariable("peak_base_shear", ("building",), "f8", "N", "largest absolute base shear over the run"),
)

#: Summaries of every case of an experiment whose scene has walls (in the base scene or a variant), after :data:`CASE_SUMMARIES`;
#: NaN for a case without walls (a variant without them).
WALL_SUMMARIES = (
    StoreVariable("peak_wall_penetration", (), "f8", "m", "largest penetration of a wall over the run and over the walls (0: no wall reached)"),
    StoreVariable("largest_wall_closure", (), "f8", "m", "largest closure toward a wall over the run and over the walls: the clearance this run needed"),
)

#: Summaries of every case of an experiment whose buildings have yielding storeys or storey heights (in the base scene or a variant),
#: after the wall summaries: per building, the largest over its storeys (NaN where the run has no such value: an elastic building's
#: ductility, a ratio without ``storey_height``, a drift ratio without ``[output] demands = true``).
STOREY_SUMMARIES = (
    StoreVariable("peak_drift_ratio", ("building",), "f8", "1", "largest peak storey drift ratio over the building's storeys (with demands and storey heights)"),
    StoreVariable("peak_ductility", ("building",), "f8", "1", "largest peak storey ductility (drift over yield drift) over the building's yielding storeys"),
    StoreVariable("residual_drift", ("building",), "f8", "m", "largest absolute residual storey drift over the building's storeys"),
    StoreVariable("residual_drift_ratio", ("building",), "f8", "1", "largest absolute residual storey drift ratio over the building's storeys"),
)

#: The kinds of limit state (an experiment's ``[limit_states]`` keys, ``stochpound.risk.LimitState``) -> the per-case summary each reads.
LIMIT_STATE_DEMANDS = {
    "drift_ratio": "peak_drift_ratio",
    "residual_drift_ratio": "residual_drift_ratio",
    "ductility": "peak_ductility",
    "floor_acceleration": "peak_floor_acceleration",
    "impact_force": "peak_impact_force",
    "isolator_displacement": "peak_sliding_displacement",
}

#: Summaries of every fixed-base reference (the studied building alone): those of a case, named ``reference_<name>``, per building no more.
REFERENCE_SUMMARIES = tuple(
    replace(v, name=f"reference_{v.name}", dims=(), long_name=v.long_name + _ALONE)
    for v in CASE_SUMMARIES
    if v.name.startswith("response_") or v.name in ("peak_total_displacement", "peak_relative_displacement")
)

_HISTORIES = (
    StoreVariable("total_displacement", ("building", "floor"), "f8", "m", "floor displacement relative to the ground (y = s + u)"),
    StoreVariable("relative_displacement", ("building", "floor"), "f8", "m", "floor displacement relative to the building's base (u)"),
    StoreVariable("sliding_displacement", ("building",), "f8", "m", "sliding displacement of the base relative to the ground (s)"),
    StoreVariable("ground_acceleration", (), "f8", "m s-2", "ground acceleration a_g"),
    StoreVariable("impact_force", ("contact",), "f8", "N", "contact force, positive in compression (0 while open)"),
    StoreVariable("base_friction_force", ("building",), "f8", "N", "force of the foundation on the base, positive to the right (0 for a fixed base)"),
    StoreVariable("base_state", ("building",), "i1", "1", "base state"),
    StoreVariable("energy_input", (), "f8", "J", "work of the ground-acceleration load (relative-motion input energy)"),
    StoreVariable("energy_kinetic", (), "f8", "J", "kinetic energy of the motion relative to the ground"),
    StoreVariable("energy_strain", (), "f8", "J", "strain energy of storeys and base restoring springs"),
    StoreVariable("energy_damping", (), "f8", "J", "energy dissipated by the storey dashpots"),
    StoreVariable("energy_friction", (), "f8", "J", "energy dissipated by base friction"),
    StoreVariable("energy_impact", (), "f8", "J", "work absorbed by the impact elements (dissipated, plus stored while closed)"),
    StoreVariable("energy_residual", (), "f8", "J", "input minus every other term (0 for an exact solution)"),
)
#: Time histories a store can keep, by name (``[output] time_histories``; stored as float, over ``time``).
TIME_HISTORIES = {v.name: v for v in _HISTORIES}
#: The fixed-base reference's kept history (with ``total_displacement``).
REFERENCE_HISTORY = StoreVariable("reference_total_displacement", ("floor",), "f8", "m", "total displacement of the studied building alone on a fixed base")

#: Columns of the table of impacts (dimension ``impact``), in store order.
IMPACT_TABLE = (
    StoreVariable("impact_contact", ("impact",), "i8", "1", "contact index of the impact (-1: a wall)"),
    StoreVariable("impact_start", ("impact",), "f8", "s", "time the impact began"),
    StoreVariable("impact_end", ("impact",), "f8", "s", "time the impact ended (end of the motion if still closed)"),
    StoreVariable("impact_duration", ("impact",), "f8", "s", "impact duration"),
    StoreVariable("impact_peak_force", ("impact",), "f8", "N", "largest contact force of the impact"),
    StoreVariable("impact_peak_time", ("impact",), "f8", "s", "time of the largest contact force"),
    StoreVariable("impact_impulse", ("impact",), "f8", "N s", "time integral of the contact force"),
    StoreVariable("impact_onset_velocity", ("impact",), "f8", "m s-1", "approach velocity (rate of penetration) at onset"),
    StoreVariable("impact_in_phase", ("impact",), "b1", "1", "both floors moving the same way at onset (false at a wall, which moves with the ground)"),
    StoreVariable("impact_complete", ("impact",), "b1", "1", "the impact ended before the end of the motion"),
)

#: Every variable of the catalogue by name (the summaries, the histories, the reference's history, the impact table).
CATALOGUE = {v.name: v for v in (*CASE_SUMMARIES, *WALL_SUMMARIES, *STOREY_SUMMARIES, *REFERENCE_SUMMARIES, *_HISTORIES, REFERENCE_HISTORY, *IMPACT_TABLE)}
