"""The building codes' separation rules, evaluated per run: ABS, SRSS (with Eurocode 8's reduction) and DDC.

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
"""

from stochpound.codes._separation_rules import EC8_REDUCTION, STORE_NAMES, contact_demands, fixed_base_cqc, separation_rules, store_contact_demands

__all__ = ["EC8_REDUCTION", "STORE_NAMES", "contact_demands", "fixed_base_cqc", "separation_rules", "store_contact_demands"]
