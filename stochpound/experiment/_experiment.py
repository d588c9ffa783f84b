"""An experiment as it runs: the store layer's grid, which chooses the motions of its stripes here.

What an experiment is (its definition, grid, cases and their scenes) is the
store layer's (:class:`stochpound.store.ExperimentGrid`), so that a store's
grid (``ds.pound.grid``) is read there. Running an experiment adds one thing
to it: with ``[intensity] selection = "conditional_spectrum"`` the motions of
every stripe are chosen (:func:`stochpound.experiment._site.stripe_selections`),
once, when first asked for; the store then records the choice.
"""

from __future__ import annotations

from functools import cached_property

from stochpound.experiment._site import StripeSelections, stripe_selections
from stochpound.store import ExperimentGrid


class Experiment(ExperimentGrid):
    """A validated experiment (:func:`~stochpound.experiment.load_experiment`): its grid, with its stripes' motions chosen.

    Parameters
    ----------
    definition : mapping or Definition
        Canonical definition (``stochpound.experiment._spec.parse_experiment``), or
        its typed form (:func:`~stochpound.experiment.read_definition`).
    text : str
        The experiment file's text (provenance).
    base_dir : str or Path
        Folder of the experiment file (record files are resolved against it).
    path : str, optional
        The experiment file, for provenance.
    """

    @cached_property
    def selection(self) -> StripeSelections | None:
        """The motions chosen for every stripe (``[intensity] selection = "conditional_spectrum"``), chosen when first asked for; None otherwise."""
        return stripe_selections(self) if self.selects_motions else None
