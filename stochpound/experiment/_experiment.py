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

    Its parameters are :class:`~stochpound.store.ExperimentGrid`'s but ``choice``: the run chooses the stripes' motions itself.
    """

    seed_override: int | None = None
    """The ``[intensity] seed`` it was loaded with instead of its file's (``load_experiment(path, seed=…)``), else None:
    its default store is then :func:`~stochpound.experiment.seed_store`'s."""

    @cached_property
    def selection(self) -> StripeSelections | None:
        """The motions chosen for every stripe (``[intensity] selection = "conditional_spectrum"``), chosen when first asked for; None otherwise."""
        return stripe_selections(self) if self.selects_motions else None
