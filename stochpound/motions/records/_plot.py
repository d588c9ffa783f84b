"""Plots of an accelerogram and of response spectra (matplotlib, headless)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stochpound.motions.records._record import Record
from stochpound.motions._arias import DEFAULT_G


def plot_record(record: Record, path: str | Path, g: float = DEFAULT_G) -> Path:
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


def plot_spectra(spectra: list[tuple[str, np.ndarray, np.ndarray]], path: str | Path, title: str, g: float = DEFAULT_G) -> Path:
    """Save a figure of response spectra: PSA (in g) against period on log–log axes.

    Parameters
    ----------
    spectra : list of (label, periods, psa)
        Periods in s, PSA in m/s²; a label of ``""`` draws a thin grey line without a legend entry.
    path : str or Path
        Output file (format from the extension).
    title : str
        Figure title.
    g : float
        m/s², to express PSA in g.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.2), layout="constrained")
    for label, periods, psa in spectra:
        style = {"lw": 0.5, "color": "0.7"} if not label else {"lw": 1.4}
        ax.loglog(periods, np.asarray(psa) / g, label=label or None, **style)
    ax.set_xlabel("period T (s)")
    ax.set_ylabel("pseudo-spectral acceleration (g)")
    ax.set_title(title, fontsize=10)
    if any(label for label, _, _ in spectra):
        ax.legend(fontsize=8)
    ax.grid(True, which="both", lw=0.3, color="0.85")
    out = Path(path)
    fig.savefig(out, dpi=150)
    plt.close(fig)
    return out
