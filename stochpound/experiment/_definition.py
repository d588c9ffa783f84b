"""The typed definition now lives in the store layer (``stochpound.store``); these names stay importable from here
only until the concurrent changes that import them (the risk chain's move to ``stochpound.risk``) are merged, then this module goes."""

from stochpound.store import FIXED_BASE, Definition, GapAxis, MotionSource, MuAxis, Output, Solver, VariantAxis, is_fixed_base, is_gap_axis, read_definition

__all__ = ["FIXED_BASE", "Definition", "GapAxis", "MotionSource", "MuAxis", "Output", "Solver", "VariantAxis", "is_fixed_base", "is_gap_axis", "read_definition"]
