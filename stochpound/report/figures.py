"""Figures of the report, each from xarray data (one function per kind of figure).

Every function returns a :class:`matplotlib.figure.Figure` with labelled
axes (units), a legend where there is more than one line, and a title that
names the record; substitute records are labelled as such by the caller's
``record_label``.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from stochpound.analysis import normal_histogram  # noqa: E402

CM = 100.0


def _figure(rows: int = 1, height: float = 3.2) -> tuple[Figure, list]:
    figure = Figure(figsize=(7.5, height * rows), layout="constrained")
    axes = figure.subplots(rows, 1, squeeze=False)[:, 0]
    return figure, list(axes)


def accelerograms(motions: dict[str, xr.DataArray]) -> Figure:
    """The ground accelerations (m/s²) against time, one panel per labelled record (Figure 3.4)."""
    figure, axes = _figure(len(motions), 2.0)
    for ax, (label, acceleration) in zip(axes, motions.items()):
        ax.plot(acceleration["time"], acceleration, lw=0.6, color="k")
        ax.set_title(label, fontsize=9)
        ax.set_ylabel("a_g (m/s²)")
    axes[-1].set_xlabel("time (s)")
    return figure


def time_history_with_impacts(run: xr.Dataset, building: str, floor: int, title: str) -> Figure:
    """Total displacement of one floor with impact markers, and the contact forces (Figure 3.6)."""
    figure, (top, bottom) = _figure(2)
    y = run["total_displacement"].sel(building=building, floor=floor)
    top.plot(run["time"], y * CM, lw=0.7, label=f"{building} floor {floor}")
    starts = run["impact_start"].values
    if len(starts):
        top.plot(starts, np.interp(starts, run["time"], y) * CM, "rv", ms=4, label="impact onsets")
    top.set_ylabel("total displacement (cm)")
    top.set_title(title, fontsize=9)
    top.legend(fontsize=8)
    for contact in run["contact"].values:
        label = f"contact {int(contact)}: floor {int(run['contact_left_floor'][contact])}"
        bottom.plot(run["time"], run["impact_force"].sel(contact=contact) / 1e3, lw=0.7, label=label)
    bottom.set_ylabel("impact force (kN)")
    bottom.set_xlabel("time (s)")
    bottom.legend(fontsize=8)
    return figure


def against(data: xr.Dataset, x: str, panels: dict[str, str], hue: str | None, title: str, x_label: str) -> Figure:
    """Summary variables against a grid axis (e.g. impacts vs gap, skewness vs μ), one panel each.

    Parameters
    ----------
    data : xarray.Dataset
        Summaries with dimension ``x`` (and ``hue`` if given).
    x : str
        The grid axis on the horizontal axis.
    panels : dict
        Variable name -> axis label (with units).
    hue : str or None
        A dimension drawn as separate labelled lines.
    title, x_label : str
    """
    figure, axes = _figure(len(panels), 2.4)
    for ax, (name, label) in zip(axes, panels.items()):
        values = data[name]
        lines = [(None, values)] if hue is None else [(v, values.sel({hue: v})) for v in values[hue].values]
        for key, line in lines:
            ax.plot(line[x], line, marker="o", ms=3, label=None if key is None else f"{hue} = {key}")
        ax.set_ylabel(label)
        if hue is not None:
            ax.legend(fontsize=8)
    axes[0].set_title(title, fontsize=9)
    axes[-1].set_xlabel(x_label)
    return figure


def histogram_with_normal(response: xr.DataArray, title: str, bins: int = 40) -> Figure:
    """Density histogram of a displacement (cm) with the fitted normal density (Figures 4.6, 4.18, 4.19)."""
    histogram = normal_histogram(response * CM, bins=bins)
    figure, (ax,) = _figure(1)
    edges = histogram["edges"].values
    ax.stairs(histogram["density"].values, edges, fill=True, alpha=0.5, label="sample")
    ax.plot(histogram["bin"], histogram["normal_density"], "r-", label=f"normal (mean {histogram.attrs['mean']:.3g}, std {histogram.attrs['std']:.3g})")
    ax.set_xlabel("total displacement (cm)")
    ax.set_ylabel("density (1/cm)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)
    return figure


def comparison(time: np.ndarray, curves: dict[str, np.ndarray], y_label: str, title: str) -> Figure:
    """Several time histories on one axis (e.g. solver vs closed form, Figures 3.2/3.3 and 4.20)."""
    figure, (ax,) = _figure(1)
    for style, (label, values) in zip(("-", "--", ":", "-."), curves.items()):
        ax.plot(time, values, style, lw=0.8, label=label)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(y_label)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)
    return figure
