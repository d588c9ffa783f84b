"""The one door to an open experiment store: the ``pound`` accessor of an xarray dataset.

``ds.pound`` (xarray's own extension point, ``xr.register_dataset_accessor``)
gives what a store is and holds, read from its attributes once per
definition: the typed definition (:class:`~stochpound.experiment.Definition`),
its intensity setting and hazard (typed), the gap axes and the selections by
meaning (contact-free, wall-free, fixed-base cases), the experiment's grid,
what ran in a case (its scene) and its impacts. The report, the command line,
the studies and the risk chain read stores through it.

The grid (cases, their ids and structures) is this layer's
(:class:`~stochpound.store.ExperimentGrid`), built from the store's definition
and, for stripes of chosen motions, the choice the store records: nothing
above this layer needs to be imported first.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import xarray as xr

from stochpound._errors import ExperimentError
from stochpound.model.scene import Scene
from stochpound.model.scene_file import scene_from_dict
from stochpound.store._gap_axes import contact_free, contact_gap_dims, gap_dims, has_contact_free, has_wall_free, wall_free, wall_gap_dims
from stochpound.store._selections import fixed_base, has_fixed_base_twins
from stochpound.store._definition import Definition, Hazard, Intensity, read_definition
from stochpound.store._grid import ExperimentGrid, Label, StoredChoice
from stochpound.store._motion_table import MotionTable
from stochpound.store._provenance import Provenance
from stochpound.model.fields import TomlTable

__all__ = ["ACCESSOR", "StoreAccessor"]

ACCESSOR = "pound"
"""The accessor's name: ``ds.pound``."""



@lru_cache(maxsize=64)
def _definition(text: str) -> Definition:
    """A stored definition, parsed once per text (a report opens the same store many times)."""
    return read_definition(text)


@lru_cache(maxsize=16)
def _grid(text: str, choice: StoredChoice | None) -> ExperimentGrid:
    """A store's grid, built once per definition (and choice of the stripes' motions)."""
    return ExperimentGrid(_definition(text), choice=choice)


@xr.register_dataset_accessor(ACCESSOR)
class StoreAccessor:
    """``ds.pound``: an experiment store's definition, grid, cases and selections.

    Parameters
    ----------
    dataset : xarray.Dataset
        An experiment store (:func:`~stochpound.open_store`), or a
        selection of one (its attributes kept).

    Examples
    --------
    >>> ds = stochpound.open_store("quickstart.nc")          # doctest: +SKIP
    >>> ds.pound.definition.gaps                            # doctest: +SKIP
    >>> ds.pound.scene(gap=0.02, mu=0.1, record="elcentro")  # doctest: +SKIP
    """

    def __init__(self, dataset: xr.Dataset) -> None:
        self._dataset = dataset

    @property
    def _text(self) -> str:
        attrs = self._dataset.attrs
        if "definition" not in attrs:
            raise ExperimentError("not a stochpound experiment store (no definition attribute)")
        return str(attrs["definition"])

    # ------------------------------------------------------------ definition

    @property
    def definition(self) -> Definition:
        """The store's definition, typed (parsed once per definition)."""
        return _definition(self._text)

    @property
    def provenance(self) -> Provenance:
        """What wrote the store and how far its runs went (its provenance attributes, typed)."""
        return Provenance.of(self._dataset)

    @property
    def sha256(self) -> str:
        """The identity of the store's runs (its ``definition_sha256`` attribute)."""
        return self.provenance.definition_sha256

    @property
    def intensity(self) -> Intensity | None:
        """The ``[intensity]`` setting the motions were scaled with, or None."""
        return self.definition.intensity

    @property
    def hazard(self) -> Hazard | None:
        """The site's hazard curve the store carries (values and provenance), or None."""
        return self.definition.hazard

    @property
    def grid(self) -> ExperimentGrid:
        """The experiment's grid (:class:`~stochpound.store.ExperimentGrid`): dimensions, cases, their scenes; built once per definition.

        With stripes of chosen motions (a conditional-spectrum selection), the
        choice is the one the store records (``selection_scale_factor``, the simulated motions' tables on ``record``).
        """
        text = self._text
        intensity = _definition(text).intensity
        chose = intensity is not None and "selection_scale_factor" in self._dataset.variables
        return _grid(text, StoredChoice.from_store(self._dataset, intensity.levels) if chose and intensity is not None else None)

    # ------------------------------------------------------------ gap axes and selections

    @property
    def gap_dims(self) -> list[str]:
        """The gap axes, in grid order."""
        return gap_dims(self._dataset)

    @property
    def contact_gap_dims(self) -> list[str]:
        """The gap axes that set contacts between buildings."""
        return contact_gap_dims(self._dataset)

    @property
    def wall_gap_dims(self) -> list[str]:
        """The gap axes that set walls only."""
        return wall_gap_dims(self._dataset)

    @property
    def has_contact_free(self) -> bool:
        """Whether every contact axis holds ``inf`` (contact-free cases)."""
        return has_contact_free(self._dataset)

    @property
    def has_wall_free(self) -> bool:
        """Whether every wall axis holds ``inf`` (wall-free cases)."""
        return has_wall_free(self._dataset)

    def contact_free(self) -> xr.Dataset:
        """The contact-free cases (``inf`` on every contact axis, those coordinates dropped)."""
        return contact_free(self._dataset)

    def wall_free(self) -> xr.Dataset:
        """The wall-free cases (``inf`` on every wall axis, those coordinates dropped)."""
        return wall_free(self._dataset)

    @property
    def has_fixed_base_twins(self) -> bool:
        """Whether the μ axis holds both the fixed base and finite values."""
        return "mu" in self._dataset.dims and has_fixed_base_twins(self._dataset["mu"].values)

    def fixed_base(self) -> xr.Dataset:
        """The fixed-base cases (μ = ∞), the ``mu`` coordinate kept."""
        return fixed_base(self._dataset)

    # ------------------------------------------------------------ cases

    def _at(self, variable: str, **labels: Label) -> np.ndarray:
        """The one value of ``variable`` at ``labels`` (labels of dimensions the store lacks ignored, one realization squeezed)."""
        present = {dim: value for dim, value in labels.items() if dim in self._dataset.dims}
        data = self._dataset[variable].sel(present)
        if "realization" in data.dims and data.sizes["realization"] == 1:
            data = data.isel(realization=0)
        if data.size != 1:
            raise ExperimentError(f"case at {labels}: {data.size} cases, expected one (give every dimension: {dict(data.sizes)})")
        return data.values.reshape(())

    def case_id(self, **labels: Label) -> str:
        """The id of the case at ``labels`` (one label on every grid dimension; a single realization needs none).

        Raises
        ------
        KeyError
            If a label is not on its dimension.
        ExperimentError
            If the labels leave more than one case.
        """
        return str(self._at("case_id", **labels))

    def scene(self, **labels: Label) -> Scene:
        """What ran in one case: its scene (structure and motion), rebuilt from the store's definition.

        A case of intensity stripes ran its record scaled to its level: the
        scene's motion carries that scale (the case's ``scale_factor``, times
        the record's own ``scale``).

        Parameters
        ----------
        **labels
            The case's label on every grid dimension of the store.

        Raises
        ------
        ExperimentError
            If the labels leave more than one case, or the case ran a synthetic
            motion scaled to a level (a generator's table has no scale).
        """
        grid = self.grid
        case = grid.case_index[self.case_id(**labels)]
        motion = grid.motion_table(case.record, case.realization)
        factor = float(self._at("scale_factor", **labels)) if "scale_factor" in self._dataset else 1.0
        if factor != 1.0:
            typed = MotionTable.of(TomlTable(motion, "motion"))
            if typed.type not in ("record", "site_motions"):
                raise ExperimentError(f"case at {labels}: its {typed.type} motion ran scaled by {factor:.9g} (scale_factor), "
                                      "which a generator's [motion] table cannot say; scale the scene's ground motion instead")
            motion["scale"] = typed.scale * factor
        return scene_from_dict({**grid.structure(case), "motion": motion})

    def impacts(self, **labels: Label) -> xr.Dataset:
        """The rows of the impact table of the cases at ``labels`` (the ``impact_*`` variables; all of them without labels), loaded."""
        store = self._dataset
        table = store[[name for name in store.data_vars if name.startswith("impact_") and store[name].dims == ("impact",)]]
        keep = np.ones(table.sizes["impact"], dtype=bool)
        for dim, label in labels.items():
            coordinate = f"impact_{dim}"
            if coordinate in table.coords:
                values = table[coordinate].values
                keep &= np.isclose(values, label) if np.issubdtype(values.dtype, np.number) else values == label
        return table.isel(impact=np.flatnonzero(keep)).load()
