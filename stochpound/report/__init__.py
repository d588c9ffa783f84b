"""Reports of experiment stores, in HTML and PDF.

* :mod:`stochpound.report.assemble`: the entry point (``stochpound report
  build``), which builds a :class:`~stochpound.report.render._document.Report`
  from stores;
* :mod:`stochpound.report.render`: the document model and its formats (HTML,
  PDF, their layout, the figure kinds, writing the output folder);
* :mod:`stochpound.report.sections`: the sections of any experiment's report
  (summary, each store's statistics and findings, separation, intensity,
  risk, the contact laws compared, methods).

A store that declares it reproduces part of a published study
(``[experiment] reproduces``) is reported by that study
(:mod:`stochpound.studies`); nothing here names an experiment.
"""
