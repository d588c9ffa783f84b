"""Pounding risk at a site: fragility, hazard, mean annual frequency, the risk-targeted separation g* and the code rules."""
