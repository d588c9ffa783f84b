"""The report as a document and its formats: the document model, HTML, PDF, their table layout, the figure kinds and the output folder."""
