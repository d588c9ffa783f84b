"""Sections of docs/benchmarks.md written by their own commands and kept when the main suite rewrites the file.

A section is the text between its two HTML-comment markers (markers included).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Section:
    """A marked section of a Markdown file.

    Attributes
    ----------
    start, end : str
        The markers (HTML comments) that open and close it.
    """

    start: str
    end: str

    def write(self, path: Path, text: str) -> None:
        """Replace the section of ``path`` with ``text`` (which holds both markers); appended if the file has none."""
        document = path.read_text() if path.exists() else ""
        if self.start in document and self.end in document:
            head, rest = document.split(self.start, 1)
            document = head + text.strip() + rest.split(self.end, 1)[1]
        else:
            document = document.rstrip() + "\n\n" + text
        path.write_text(document if document.endswith("\n") else document + "\n")

    def kept(self, document: str) -> str:
        """The section of ``document``, markers included ("" if it has none)."""
        if self.start not in document or self.end not in document:
            return ""
        return self.start + document.split(self.start, 1)[1].split(self.end, 1)[0] + self.end


def keep_sections(old: str, new: str, sections: tuple[Section, ...]) -> str:
    """The main suite's new document ``new`` with the ``sections`` of ``old`` (its previous version) appended in order."""
    kept = [text for text in (section.kept(old) for section in sections) if text]
    return "\n\n".join([new.rstrip(), *kept]) + "\n"
