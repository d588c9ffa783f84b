"""The building codes' separation rules, evaluated per run: ABS, SRSS (with Eurocode 8's reduction) and DDC; and ASCE 7 chapter 17.

:func:`contact_demands` reads the rules' inputs at every contact of a
contact-free run (the two floors' peak displacements, their correlation,
the peak closure), :func:`store_contact_demands` the same from an
experiment store's per-case summaries, :func:`separation_rules` turns them
into each rule's gap and :func:`fixed_base_cqc` gives the CQC correlation of
the two buildings' fixed-base modes. The experiment's per-case summaries,
the separation statistics (:mod:`stochpound.analysis`, which gives these
names to its users) and the code rules in risk terms
(:mod:`stochpound.risk`) all evaluate the rules here: this package imports
none of them.

:func:`chapter17_design` designs a building on a sliding base by ASCE 7-16
§17.5 (D_M, D_TM, V_b, V_st, V_s and the limits of §17.5.4.3 at lower- and
upper-bound friction) and :func:`isolated_separation` gives its separation
from a fixed-base neighbour, D_TM + the neighbour's δ_M.
"""

from stochpound.codes._isolation import (
    Chapter17Design,
    IsolatedPlan,
    IsolatedSeparation,
    IsolationBound,
    MceSpectrum,
    SlidingBase,
    chapter17_design,
    damping_coefficient,
    isolated_separation,
    isolator_displacement,
)
from stochpound.codes._separation_rules import EC8_REDUCTION, STORE_NAMES, contact_demands, fixed_base_cqc, separation_rules, store_contact_demands

__all__ = [
    "Chapter17Design",
    "IsolatedPlan",
    "IsolatedSeparation",
    "IsolationBound",
    "MceSpectrum",
    "SlidingBase",
    "chapter17_design",
    "damping_coefficient",
    "isolated_separation",
    "isolator_displacement",
    "EC8_REDUCTION", "STORE_NAMES", "contact_demands", "fixed_base_cqc", "separation_rules", "store_contact_demands"]
