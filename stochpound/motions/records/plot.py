"""Plot of an accelerogram (matplotlib, headless)."""

from __future__ import annotations

from pathlib import Path

from stochpound.motions.records.record import Record
from stochpound.motions.records.statistics import STUDY_G


def plot_record(record: Record, path: str | Path, g: float = STUDY_G) -> Path:
    """Save a figure of the record's acceleration (in g) against time.

    Parameters
    ----------
    record : Record
        The record.
    path : str or Path
        Output file; the format follows the extension (``.png``, ``.pdf``, ``.svg``).
    g : float
        m/s², to express m/s² records in g.

    Returns
    -------
    Path
        The written file.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    in_g = record.acceleration(g=g) / g
    fig, ax = plt.subplots(figsize=(9.0, 3.2), layout="constrained")
    ax.plot(record.time, in_g, lw=0.6, color="k")
    ax.axhline(0.0, lw=0.4, color="0.6")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("ground acceleration (g)")
    ax.set_xlim(0.0, record.duration)
    title = record.name
    if "SUBSTITUTE" in record.provenance:
        title += "  (SUBSTITUTE)"
    ax.set_title(title, fontsize=10)
    out = Path(path)
    fig.savefig(out, dpi=150)
    plt.close(fig)
    return out
