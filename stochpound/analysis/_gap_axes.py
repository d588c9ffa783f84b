"""The gap axes now live in the store layer (``stochpound.store``); these names stay importable from here
only until the risk chain's move to ``stochpound.risk`` (a concurrent change) is merged, then this module goes."""

from stochpound.store import SETS, contact_free, contact_gap_dims, gap_dims, has_contact_free, has_wall_free, is_gap_axis, wall_free, wall_gap_dims, with_contacts, with_walls

__all__ = ["SETS", "contact_free", "contact_gap_dims", "gap_dims", "has_contact_free", "has_wall_free", "is_gap_axis", "wall_free", "wall_gap_dims", "with_contacts", "with_walls"]
