"""Sphinx configuration of the stochpound documentation.

Build: ``python -m sphinx -W --keep-going -b html docs OUT`` (about half a
minute on two cores, the gallery's scripts included). The build is nitpicky:
every cross-reference must resolve, warnings are errors.
"""

import stochpound

project = "stochpound"
author = "The stochpound developers"
copyright = "2026, The stochpound developers"
release = version = stochpound.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
templates_path = ["_templates"]
# examples/ holds the gallery's sources (sphinx-gallery turns them into auto_examples/);
# notebooks/ is executed by the test suite on the quick-start store, not by the build.
exclude_patterns = ["_build", "notebooks", "figures/*.py", "examples", "auto_examples/*.ipynb", "auto_examples/*.py"]

myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections give the types (and units)
autosummary_generate = True  # one page per documented object, under api/ (see api.md)
autosummary_imported_members = False
numpydoc_show_class_members = False
# parameter and return types link to the public classes they name; other words
# (builtins, other projects' types, "optional", ...) stay plain text
numpydoc_xref_param_type = True
numpydoc_xref_ignore = "all"
numpydoc_xref_aliases = {
    name: f"stochpound.{module}.{name}" if module else f"stochpound.{name}"
    for module, names in {
        "model": ["Scene", "Building", "InitialState", "Base", "Contact", "Wall", "ImpactElement"],
        "experiment": ["Experiment", "Dim", "Case", "RunReport", "StatusReport", "ExperimentError", "Definition", "GapAxis", "MuAxis",
                       "VariantAxis", "MotionSource", "Output", "Solver"],
        "store": ["StoreAccessor", "Intensity", "Hazard", "Design", "DesignEc8", "LimitStates", "LimitStateCapacities", "Site", "StoreVariable", "ExperimentGrid", "Point"],
        "motions": ["Envelope", "FilteredWhiteNoise", "SoilPreset", "Measure"],
        "motions.records": ["Record", "RegistryEntry", "RawSeries", "RecordStatistics"],
        "": ["SceneError", "RecordError", "SiteError", "StochpoundError"],
    }.items()
    for name in names
}

# Every cross-reference must resolve. The build needs no network, so other
# projects' inventories (intersphinx) are not loaded: references to their
# objects cannot resolve and are accepted here by namespace, and only these.
nitpicky = True
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|scipy|xarray|pandas|matplotlib|dask|numba|click)(\..+)?"),
    # numpydoc's built-in type aliases (float, int, None, sequence, array_like, ...) point into
    # Python's and numpy's inventories
    (r"py:.*|std:term|std:ref", r"(python|numpy):.+"),
    # private helpers (a leading underscore) are named in docstrings for
    # contributors but are not documented
    (r"py:.*", r"(.+\.)?_[A-Za-z]\w*"),
]

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",  # every example is executed
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "remove_config_comments": True,
    "download_all_examples": False,
    "show_memory": False,
    "image_scrapers": ("matplotlib",),
    "matplotlib_animations": False,
    "min_reported_time": 1,
    # "Examples using X" at the foot of each API page (docs/_templates/autosummary)
    "doc_module": ("stochpound",),
    "backreferences_dir": "generated/backreferences",
}

html_theme = "pydata_sphinx_theme"
html_title = f"stochpound {release}"
html_theme_options = {"navigation_with_keys": False}
html_static_path = []
