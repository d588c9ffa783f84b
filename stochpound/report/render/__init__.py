"""The report as a document and its formats: the document model, HTML, PDF, their table layout, the figure kinds and the output folder."""

from stochpound.report.render import _figures as figures
from stochpound.report.render._document import Block, FigureItem, Paragraph, Report, Section, Table
from stochpound.report.render.output import write_report

__all__ = ["Block", "FigureItem", "Paragraph", "Report", "Section", "Table", "figures", "write_report"]
