"""Sphinx configuration of the stochpound documentation (``python -m sphinx -W -b html docs OUT``)."""

import stochpound

project = "stochpound"
author = "The stochpound developers"
copyright = "2026, The stochpound developers"
release = version = stochpound.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "notebooks", "figures/*.py"]

myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections give the types (and units)
numpydoc_show_class_members = False
numpydoc_xref_param_type = False

html_theme = "pydata_sphinx_theme"
html_title = f"stochpound {release}"
html_theme_options = {"navigation_with_keys": False}
html_static_path = []
