"""Kinds of report figures, drawn from plain arrays (one function per kind).

Every function returns a :class:`matplotlib.figure.Figure` (not attached to
pyplot, so building many figures keeps no global state) with labelled axes
(units), a legend where there is more than one line, and a title. The callers
(the report's sections and the studies' figures) name the record and label
substitutes as such.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
import xarray as xr
from matplotlib.artist import Artist
from matplotlib.figure import Figure

from stochpound.analysis import normal_histogram

MAX_PANELS = 16
"""Most panels in one figure."""

#: Line styles cycled over the lines of one panel.
STYLES = ("-", "--", ":", "-.")


def _figure(rows: int = 1, height: float = 3.0, columns: int = 1) -> tuple[Figure, list]:
    figure = Figure(figsize=(7.5, height * rows), layout="constrained")
    axes = figure.subplots(rows, columns, squeeze=False)
    return figure, list(axes.ravel())


def traces(
    time: np.ndarray, panels: Mapping[str, Mapping[str, np.ndarray]], title: str, height: float = 2.2, y_label: str | None = None
) -> Figure:
    """Time histories, one panel per entry ({line label -> values}).

    Used for the accelerograms (Figure 3.4), the harmonic check (Figures
    3.2–3.3) and time histories of several configurations (Figure 4.20).
    The panels' keys are their y labels or, when ``y_label`` (shared by
    every panel) is given, their titles.
    """
    figure, axes = _figure(len(panels), height)
    for ax, (key, lines) in zip(axes, panels.items()):
        for style, (label, values) in zip(_cycle(len(lines)), lines.items()):
            ax.plot(time, values, style, lw=0.7, label=label)
        if y_label is None:
            ax.set_ylabel(key)
        else:
            ax.set_ylabel(y_label)
            ax.set_title(key, fontsize=8)
        if len(lines) > 1:
            ax.legend(fontsize=7, loc="upper right")
    figure.suptitle(title, fontsize=9)
    axes[-1].set_xlabel("time (s)")
    return figure


def time_history_with_impacts(
    time: np.ndarray,
    displacement: np.ndarray,
    impact_starts: np.ndarray,
    forces: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
    displacement_label: str,
    title: str,
) -> Figure:
    """A displacement (cm) with markers at impact onsets, and each contact's force (kN) in a panel of its own (Figure 3.6).

    Parameters
    ----------
    time : numpy.ndarray
        s.
    displacement : numpy.ndarray
        m, on ``time``.
    impact_starts : numpy.ndarray
        Impact onset times, s.
    forces : mapping
        Contact label -> (its force on ``time`` in N, the peak times of its
        impacts in s, their located peak forces in N).
    displacement_label, title : str
    """
    figure, axes = _figure(1 + len(forces), 2.2)
    top = axes[0]
    top.plot(time, displacement * 100.0, lw=0.7, label=displacement_label)
    if len(impact_starts):
        top.plot(impact_starts, np.interp(impact_starts, time, displacement) * 100.0, "rv", ms=4, label=f"impact onsets ({len(impact_starts)})")
    top.set_ylabel("total displacement (cm)")
    top.set_title(title, fontsize=9)
    top.legend(fontsize=7, loc="upper right")
    step = float(time[1] - time[0])
    for ax, (label, (force, peak_times, peaks)) in zip(axes[1:], forces.items()):
        ax.plot(time, force / 1e3, lw=0.6, color="0.45", label=f"sampled every {step:g} s")
        ax.plot(peak_times, peaks / 1e3, "o", ms=3.5, color="C3", label=f"located peaks ({len(peaks)} impacts)")
        ax.set_ylabel("force (kN)")
        ax.set_title(label, fontsize=8)
        ax.legend(fontsize=7, loc="upper right")
    for ax in axes[1:]:
        ax.sharex(axes[0])
    axes[-1].set_xlabel("time (s)")
    return figure


def histories_with_events(lines: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray]], title: str, y_label: str, zoom: tuple[float, float]) -> Figure:
    """Time histories with markers at events (e.g. impact onsets), over the whole record and over ``zoom`` (s).

    Parameters
    ----------
    lines : mapping
        Label -> (times in s, values on them, event times in s).
    title, y_label : str
    zoom : tuple of float
        The time window of the second panel, s.
    """
    figure, axes = _figure(2, 2.6)
    for ax in axes:
        for style, (label, (time, values, events)) in zip(_cycle(len(lines)), lines.items()):
            (line,) = ax.plot(time, values, style, lw=0.9, label=label)
            if len(events):
                ax.plot(events, np.interp(events, time, values), "v", color=line.get_color(), ms=5)
        ax.set_ylabel(y_label)
        ax.grid(True, lw=0.3, alpha=0.5)
    axes[1].set_xlim(*zoom)
    axes[0].legend(fontsize=7)
    axes[0].set_title(title, fontsize=9)
    axes[1].set_title(f"{zoom[0]:.1f} to {zoom[1]:.1f} s", fontsize=8)
    axes[1].set_xlabel("time (s)")
    return figure


def against(
    x: np.ndarray, panels: Mapping[str, Mapping[str, np.ndarray]], title: str, x_label: str, log_panels: Sequence[str] = ()
) -> Figure:
    """Summaries against a grid axis (impacts vs gap, skewness vs μ, ...), one panel per entry.

    Parameters
    ----------
    x : numpy.ndarray
        The grid axis's values.
    panels : mapping
        "quantity (unit)" -> {line label -> values on ``x``}; the quantity
        titles the panel, the unit labels its y axis. NaN values are not drawn.
    title, x_label : str
    log_panels : sequence of str
        Panels (keys) drawn on a logarithmic y axis.
    """
    figure, axes = _figure(len(panels), 2.3)
    for ax, (key, lines) in zip(axes, panels.items()):
        for style, (label, values) in zip(_cycle(len(lines)), lines.items()):
            ax.plot(x, values, style, marker="o", ms=3, lw=1.0, label=label)
        quantity, _, unit = key.rpartition(" (")
        ax.set_title(quantity or key, fontsize=8)
        ax.set_ylabel(unit.rstrip(")") if quantity else "")
        if key in log_panels:
            ax.set_yscale("log")
        if len(lines) > 1:
            ax.legend(fontsize=7)
    figure.suptitle(title, fontsize=9)
    axes[-1].set_xlabel(x_label)
    return figure


def histograms_with_normal(samples: Mapping[str, xr.DataArray], title: str, bins: int = 40) -> Figure:
    """Density histograms of displacements (m, drawn in cm) with their fitted normal densities (Figures 4.6, 4.18, 4.19).

    Parameters
    ----------
    samples : mapping
        Panel title -> sample (every element counts once).
    title : str
    """
    columns = 2 if len(samples) > 1 else 1
    rows = -(-len(samples) // columns)
    figure, axes = _figure(rows, 2.6, columns)
    for ax, (label, sample) in zip(axes, samples.items()):
        histogram = normal_histogram(sample * 100.0, bins=bins)
        ax.stairs(histogram["density"].values, histogram["edges"].values, fill=True, alpha=0.5, label="sample")
        fitted = f"normal: mean {histogram.attrs['mean']:.3g}, std {histogram.attrs['std']:.3g} cm"
        ax.plot(histogram["bin"], histogram["normal_density"], "r-", lw=1.0, label=fitted)
        ax.set_title(label, fontsize=8)
        ax.set_xlabel("total displacement (cm)")
        ax.set_ylabel("density (1/cm)")
        ax.legend(fontsize=6)
    for ax in axes[len(samples):]:
        ax.set_visible(False)
    figure.suptitle(title, fontsize=9)
    return figure


@dataclass(frozen=True)
class Curve:
    """One line of a panel of :func:`panel_grid`.

    Attributes
    ----------
    label : str
        Its legend entry (curves with the same label share one entry).
    x : numpy.ndarray
        Abscissae; with ``y`` None, a sample drawn as its empirical CDF (NaN left out).
    y, lower, upper : numpy.ndarray, optional
        Ordinates and a band between ``lower`` and ``upper`` (e.g. a 95 % interval).
    color : Any
        A matplotlib colour.
    style : str
        Line style.
    marker : str
        Marker at each point ("" for none).
    gid : str
        Set on every artist of the curve (:func:`stochpound.report.sections._facets.cell_gid`).
    """

    label: str
    x: np.ndarray
    y: np.ndarray | None = None
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    color: Any = "C0"
    style: str = "-"
    marker: str = ""
    gid: str = ""


def panel_grid(
    panels: Mapping[str, Sequence[Curve]],
    title: str,
    x_label: str,
    y_label: str,
    *,
    x_ticks: Mapping[float, str] | None = None,
    log_x: bool = False,
    y_limits: tuple[float, float] | None = None,
    legend_title: str = "",
) -> Figure:
    """Panels of curves (with bands, or empirical CDFs) in a grid sharing axes and one legend.

    Parameters
    ----------
    panels : mapping
        Panel title -> its curves.
    title : str
        The figure's title.
    x_label, y_label : str
        Axis labels with units (shown once per row and column).
    x_ticks : mapping, optional
        Tick positions and labels (e.g. a categorical μ axis with "fixed").
    log_x : bool
        A logarithmic x axis (positive values only are drawn).
    y_limits : tuple, optional
        Limits of every y axis.
    legend_title : str
        Title of the figure's legend.
    """
    columns = 4 if len(panels) > 9 else min(len(panels), 3)
    rows = -(-len(panels) // columns)
    # a fixed layout (inches): constrained layout costs seconds on a grid of panels
    legend, top, bottom, left = 0.55, 0.45, 0.5, 0.65
    height = top + bottom + legend + 1.75 * rows
    figure = Figure(figsize=(7.5, height))
    axes = figure.subplots(
        rows, columns, squeeze=False, sharex=True, sharey=True,
        gridspec_kw={"left": left / 7.5, "right": 1 - 0.15 / 7.5, "top": 1 - top / height, "bottom": (bottom + legend) / height, "hspace": 0.45, "wspace": 0.12},
    )
    entries: dict[str, Artist] = {}
    for ax, (panel, curves) in zip(axes.ravel(), panels.items()):
        for curve in curves:
            entries.setdefault(curve.label, _draw(ax, curve))
        ax.set_title(panel, fontsize=7.5)
        ax.tick_params(labelsize=7)
        ax.grid(True, lw=0.3, alpha=0.5)
        if log_x:
            ax.set_xscale("log")
        if x_ticks is not None:
            ax.set_xticks(list(x_ticks), list(x_ticks.values()))
        if y_limits is not None:
            ax.set_ylim(*y_limits)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel(y_label, fontsize=8)
    for column in range(columns):
        last = max(r for r in range(rows) if r * columns + column < len(panels))
        axes[last, column].set_xlabel(x_label, fontsize=8)
        axes[last, column].xaxis.set_tick_params(labelbottom=True)
    figure.suptitle(title, fontsize=9, y=1 - 0.12 / height)
    if len(entries) > 1:
        figure.legend(list(entries.values()), list(entries), loc="lower center", bbox_to_anchor=(0.5, 0.02 / height),
                      ncols=min(len(entries), 6), fontsize=7, title=legend_title or None, title_fontsize=7)
    return figure


def _draw(ax: Any, curve: Curve) -> Artist:
    """Draw one curve (and its band) on ``ax``; return the artist for the legend."""
    if curve.y is None:
        sample = np.asarray(curve.x, dtype=float)
        line = ax.ecdf(sample[np.isfinite(sample)], color=curve.color, linestyle=curve.style, lw=1.0)
    else:
        (line,) = ax.plot(curve.x, curve.y, color=curve.color, linestyle=curve.style, marker=curve.marker or None, ms=3, lw=1.0)
        if curve.lower is not None:
            band = ax.fill_between(curve.x, curve.lower, curve.upper, color=curve.color, alpha=0.15, linewidth=0)
            band.set_gid(curve.gid)
    line.set_gid(curve.gid)
    return line


def _cycle(count: int) -> list[str]:
    return [STYLES[i % len(STYLES)] for i in range(count)]


Value = TypeVar("Value")
"""A value of a grid's dimension (a label of a panel)."""


def spread_panels(grid: Mapping[str, Sequence[Value]], max_panels: int = MAX_PANELS) -> list[tuple[list[dict[str, Value]], dict[str, Value]]]:
    """Every combination of ``grid`` (dimension -> values) spread over figures of at most ``max_panels`` panels: per figure,
    its panels' labels and the labels its panels share. The outermost dimensions are split off into separate figures until
    the rest fits; an empty grid gives one figure with one panel."""
    dims = list(grid)
    split = 0
    while split < len(dims) and math.prod(len(grid[d]) for d in dims[split:]) > max_panels:
        split += 1
    outer, inner = dims[:split], dims[split:]
    result = []
    for shared in itertools.product(*(grid[d] for d in outer)):
        panels = [dict(zip(inner, combination)) for combination in itertools.product(*(grid[d] for d in inner))]
        result.append((panels, dict(zip(outer, shared))))
    return result


def line_colours(dim: str | None, values: Sequence[Any]) -> list[Any]:
    """One colour per value of the line dimension: a sequential map for numbers (∞, a fixed base, in black), a qualitative one otherwise."""
    from matplotlib import colormaps

    if dim is None:
        return ["C0"] * len(values)
    numeric = [v.item() if isinstance(v, np.generic) else v for v in values]
    if all(isinstance(v, float) for v in numeric):
        finite = [v for v in numeric if not math.isinf(v)]
        scale = colormaps["viridis"]
        positions = np.linspace(0.0, 0.9, len(finite)) if len(finite) > 1 else [0.0]
        ranks = {v: p for v, p in zip(sorted(finite), positions)}
        return ["black" if math.isinf(v) else scale(ranks[v]) for v in numeric]
    return [f"C{i % 10}" for i in range(len(values))]


RATE_DECADES = 6
"""The most decades of annual rate a rate axis spans below its largest rate (smaller rates are off the figure)."""


def rate_limits(rates: Any, references: Any = ()) -> tuple[float, float]:
    """Limits (1/yr) of a logarithmic rate axis from the positive finite rates drawn and reference lines (targets).

    Half the smallest to twice the largest, but no more than ``RATE_DECADES``
    decades below the largest: a bootstrap band or a far tail down to 1e-300
    would otherwise squash the curves into a line. (1e-6, 1) when nothing is positive.
    """
    values = np.concatenate([np.ravel(np.asarray(rates, dtype=float)), np.ravel(np.asarray(references, dtype=float))])
    values = values[np.isfinite(values) & (values > 0.0)]
    if values.size == 0:
        return 1e-6, 1.0
    top = 2.0 * float(values.max())
    return max(0.5 * float(values.min()), top * 10.0**-RATE_DECADES), top
