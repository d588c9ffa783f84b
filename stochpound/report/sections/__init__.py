"""The sections of the report of any experiment's stores, and what they read the stores with."""
