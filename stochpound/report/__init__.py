"""Reports of experiment stores, in HTML and PDF.

* :mod:`stochpound.report.assemble`: the entry point (``stochpound report
  build``), which builds a :class:`~stochpound.report.Report` from stores;
* :mod:`stochpound.report.render`: the document model and its formats (HTML,
  PDF, their layout, the figure kinds, writing the output folder);
* :mod:`stochpound.report.sections`: the sections of any experiment's report
  (summary, each store's statistics and findings, separation, intensity,
  risk, the contact laws compared, methods).

A store that declares it reproduces part of a published study
(``[experiment] reproduces``) is reported by that study
(:mod:`stochpound.studies`); nothing here names an experiment.

The building blocks are public here (docs/api.md): a study's package or a
user's script makes :class:`Section` objects of :class:`Paragraph`,
:class:`Table` and :class:`FigureItem` blocks, and :func:`build_report` and
:func:`write_report` build and write a report of stores.
"""

from stochpound.report.assemble import assemble_report as build_report
from stochpound.report.render import Block, FigureItem, Paragraph, Report, Section, Table, write_report

__all__ = ["Block", "FigureItem", "Paragraph", "Report", "Section", "Table", "build_report", "write_report"]
