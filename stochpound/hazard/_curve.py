"""Seismic hazard curves: the mean annual rate λ(x) at which an intensity measure exceeds x at a site.

A :class:`HazardCurve` is a table (interpolated linearly in log–log, the
usual assumption of hazard tools: λ is locally a power law) or a power law
λ(x) = k0 x^(−k) (Cornell et al. 2002), given or fitted through two points.
Intensities are in the units the user chose (g for acceleration measures in
an experiment, as its ``levels``), rates in 1/yr.

Occurrences are Poisson: the probability of at least one exceedance in t
years is P = 1 − exp(−λ t), so 2 % in 50 years is λ = −ln(0.98)/50 =
4.04e-4 /yr (:func:`rate_from_probability`).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from stochpound._data_files import bundled_data_dir
from stochpound._text_files import read_text_file, written_or_returned
from stochpound.motions import Measure

BUNDLED_FOLDER = "hazard"
"""Name of the bundled hazard folder (``data/hazard/`` in the repository, with its ``SOURCES.md``)."""
BUNDLED_DAMPING = 0.05
"""Damping ratio of the bundled spectral-acceleration curves."""
BUNDLED_UNITS = "g"
"""Units of the bundled curves' intensities."""
_BUNDLED_MEASURE = re.compile(r"_(?:(pga)|sa(\d+)p(\d+)s)$")


def rate_from_probability(probability: ArrayLike, years: float = 50.0) -> np.ndarray:
    """Annual rate λ = −ln(1 − P)/t (1/yr) of an event with probability P in ``years`` (Poisson)."""
    p = np.asarray(probability, dtype=float)
    if not np.all((p > 0.0) & (p < 1.0)):
        raise ValueError(f"probability: must be in (0, 1), got {probability!r}")
    _check_positive("years", years)
    return -np.log1p(-p) / years


def probability_from_rate(rate: ArrayLike, years: float = 50.0) -> np.ndarray:
    """Probability 1 − exp(−λ t) of at least one event in ``years`` at annual rate λ (Poisson)."""
    _check_positive("years", years)
    return -np.expm1(-np.asarray(rate, dtype=float) * years)


def return_period(rate: ArrayLike) -> np.ndarray:
    """Mean return period 1/λ (yr) of an annual rate λ (1/yr); inf for λ = 0."""
    with np.errstate(divide="ignore"):
        return 1.0 / np.asarray(rate, dtype=float)


class HazardCurve:
    """Annual rate of exceedance λ(x) of an intensity measure x at a site.

    Parameters
    ----------
    im : sequence of float
        Intensities x (units of the measure, e.g. g), positive and strictly increasing.
    rate : sequence of float
        λ(x), annual rates of exceedance (1/yr), positive and strictly decreasing.
    extrapolate : bool
        Outside [im[0], im[-1]] the table is unknown: by default evaluating it
        there raises ``ValueError``. ``True`` extends its first and last
        segments as straight lines in log–log (power laws) and records in
        :attr:`extrapolated` that it did.
    measure, units, source : str
        Description kept for reports (e.g. ``"PGA"``, ``"g"``, the provenance).

    Notes
    -----
    ``hz(x)`` interpolates ln λ linearly in ln x. A power law
    (:meth:`power_law`) has no range limits.
    """

    def __init__(self, im: Sequence[float], rate: Sequence[float], *, extrapolate: bool = False,
                 measure: str = "", units: str = "", source: str = "") -> None:
        x = np.asarray(im, dtype=float)
        y = np.asarray(rate, dtype=float)
        if x.ndim != 1 or x.size < 2:
            raise ValueError(f"im: must be a 1-D sequence of at least 2 intensities, got {im!r}")
        if y.shape != x.shape:
            raise ValueError(f"rate: must have one value per intensity ({x.size}), got shape {y.shape}")
        if not np.all(np.isfinite(x) & (x > 0.0)):
            raise ValueError(f"im: every intensity must be finite and > 0, got {im!r}")
        if not np.all(np.diff(x) > 0.0):
            raise ValueError("im: intensities must be strictly increasing")
        if not np.all(np.isfinite(y) & (y > 0.0)):
            raise ValueError(f"rate: every annual rate must be finite and > 0 (1/yr), got {rate!r}")
        if not np.all(np.diff(y) < 0.0):
            raise ValueError("rate: annual rates of exceedance must be strictly decreasing with im")
        self.im, self.rate = x, y
        self._log_im, self._log_rate = np.log(x), np.log(y)
        self.extrapolate = bool(extrapolate)
        self.measure, self.units, self.source = measure, units, source
        self.power = None
        self.extrapolated = False
        """True once the curve was evaluated outside its table (only possible with ``extrapolate``)."""

    # ------------------------------------------------------------ constructors

    @classmethod
    def power_law(cls, k0: float, k: float, *, measure: str = "", units: str = "", source: str = "") -> HazardCurve:
        """The power law λ(x) = k0 x^(−k) (1/yr), for every x > 0.

        Parameters
        ----------
        k0 : float
            λ at x = 1 (1/yr, for x in the measure's units), > 0.
        k : float
            The log–log slope, > 0.
        """
        _check_positive("k0", k0)
        _check_positive("k", k)
        curve = cls([1.0, np.e], [k0, k0 * np.exp(-k)], extrapolate=True, measure=measure, units=units,
                    source=source or f"power law {k0:g} x^-{k:g}")
        curve.power = (float(k0), float(k))
        return curve

    @classmethod
    def power_law_through(cls, first: tuple[float, float], second: tuple[float, float], **description: str) -> HazardCurve:
        """The power law through two points (im, rate), e.g. the 10 %/50 yr and 2 %/50 yr intensities.

        >>> hz = HazardCurve.power_law_through((0.4, rate_from_probability(0.10)), (0.8, rate_from_probability(0.02)))
        >>> round(float(hz.power[1]), 3)  # slope k
        2.383
        """
        (x1, y1), (x2, y2) = first, second
        for name, value in (("first im", x1), ("first rate", y1), ("second im", x2), ("second rate", y2)):
            _check_positive(name, value)
        if x1 == x2 or (y2 - y1) * (x2 - x1) >= 0.0:
            raise ValueError(f"points: the rate must decrease as the intensity increases, got {first!r} and {second!r}")
        k = -np.log(y2 / y1) / np.log(x2 / x1)
        return cls.power_law(y1 * x1**k, k, **description)

    @classmethod
    def from_file(cls, path: str | Path, *, extrapolate: bool = False, measure: str = "", units: str = "") -> HazardCurve:
        """A table read from a CSV file of rows ``im, rate`` (annual rate of exceedance, 1/yr).

        Lines starting with ``#`` are comments (keep the provenance there)
        and are stored in ``source``; a first row that is not numeric
        (column names) is skipped. Any further columns are ignored.
        """
        path = Path(path)
        comments, rows = [], []
        for number, line in enumerate(read_text_file(path).splitlines(), start=1):
            text = line.strip()
            if not text:
                continue
            if text.startswith("#"):
                comments.append(text.lstrip("#").strip())
                continue
            fields = next(csv.reader([text]))
            try:
                rows.append((float(fields[0]), float(fields[1])))
            except (ValueError, IndexError):
                if rows:
                    raise ValueError(f"{path}:{number}: expected two numbers 'im, rate', got {text!r}") from None
        if not rows:
            raise ValueError(f"{path}: no rows of 'im, rate'")
        im, rate = zip(*rows)
        return cls(im, rate, extrapolate=extrapolate, measure=measure, units=units,
                   source="\n".join(comments) or str(path))

    def to_csv(self, path: str | Path | None = None) -> str | None:
        """The table as the CSV file :meth:`from_file` reads back, the same intensities, rates and ``source``: ``source`` as
        ``#`` comment lines, a header ``im,rate``, one row per intensity, every number written exactly. The text, or None
        once written to ``path``.

        Parameters
        ----------
        path : str or Path, optional
            Where to write the curve's file; None returns its text.

        Raises
        ------
        ValueError
            A power law (:meth:`power_law`): it has no table.
        """
        if self.power is not None:
            raise ValueError("to_csv: a power law has no table to write (HazardCurve.power_law)")
        text = "".join(f"# {line}\n" for line in self.source.splitlines())
        text += "im,rate\n" + "".join(f"{float(x)!r},{float(y)!r}\n" for x, y in zip(self.im, self.rate))
        return written_or_returned(text, path)

    @classmethod
    def bundled(cls, name: str, *, extrapolate: bool = False) -> HazardCurve:
        """A hazard curve shipped with stochpound (``data/hazard/<name>.csv``; :func:`~stochpound.analysis.bundled_curves` lists them)."""
        return cls.from_file(bundled_path(name), extrapolate=extrapolate, units=BUNDLED_UNITS)

    # ------------------------------------------------------------ evaluation

    @property
    def support(self) -> tuple[float, float]:
        """The intensities (lower, upper) over which the curve is defined: the table's, or (0, inf) when extrapolating."""
        return (0.0, np.inf) if self.extrapolate else (float(self.im[0]), float(self.im[-1]))

    def __call__(self, x: ArrayLike) -> np.ndarray:
        """λ(x), the annual rate (1/yr) at which the intensity exceeds ``x`` (log–log interpolation)."""
        values = np.asarray(x, dtype=float)
        if np.any(np.isnan(values)) or np.any(values < 0.0):
            raise ValueError(f"x: intensities must be >= 0, got {x!r}")
        outside = (values < self.im[0]) | (values > self.im[-1])
        if np.any(outside):
            if not self.extrapolate:
                raise ValueError(f"x: outside the hazard table [{self.im[0]:g}, {self.im[-1]:g}]"
                                 f"{' ' + self.units if self.units else ''}; extrapolate it (extrapolate=True; "
                                 "stochpound risk --extrapolate; [hazard] extrapolate = true) to extend it as a power law")
            if self.power is None:
                self.extrapolated = True
        with np.errstate(divide="ignore"):
            u = np.log(values)
        return np.exp(self.log_rate(u))

    def log_rate(self, log_im: ArrayLike) -> np.ndarray:
        """ln λ at ln x = ``log_im``, the end segments extended as straight lines (no range check: the caller's)."""
        u = np.asarray(log_im, dtype=float)
        lx, ly = self._log_im, self._log_rate
        inside = np.interp(u, lx, ly)
        below = ly[0] + (u - lx[0]) * (ly[1] - ly[0]) / (lx[1] - lx[0])
        above = ly[-1] + (u - lx[-1]) * (ly[-1] - ly[-2]) / (lx[-1] - lx[-2])
        return np.where(u < lx[0], below, np.where(u > lx[-1], above, inside))

    def intensity_at(self, rate: ArrayLike) -> np.ndarray:
        """The intensity x with λ(x) = ``rate`` (1/yr): the inverse of the curve.

        E.g. ``hz.intensity_at(rate_from_probability(0.02, 50))``, the
        2 %/50 yr intensity (ASCE 7's MCE_R level when the curve is the site's).
        """
        r = np.asarray(rate, dtype=float)
        if not np.all(np.isfinite(r) & (r > 0.0)):
            raise ValueError(f"rate: must be finite and > 0 (1/yr), got {rate!r}")
        v = np.log(r)
        lx, ly = self._log_im, self._log_rate
        outside = (r > self.rate[0]) | (r < self.rate[-1])
        if np.any(outside):
            if not self.extrapolate:
                raise ValueError(f"rate: outside the hazard table's rates [{self.rate[-1]:g}, {self.rate[0]:g}] 1/yr; "
                                 "extrapolate it (extrapolate=True; stochpound risk --extrapolate) to extend it as a power law")
            if self.power is None:
                self.extrapolated = True
        inside = np.interp(-v, -ly, lx)
        below = lx[0] + (v - ly[0]) * (lx[1] - lx[0]) / (ly[1] - ly[0])
        above = lx[-1] + (v - ly[-1]) * (lx[-1] - lx[-2]) / (ly[-1] - ly[-2])
        return np.exp(np.where(r > self.rate[0], below, np.where(r < self.rate[-1], above, inside)))

    def probability(self, x: ArrayLike, years: float = 50.0) -> np.ndarray:
        """Probability that the intensity exceeds ``x`` at least once in ``years`` (Poisson)."""
        return probability_from_rate(self(x), years)

    def return_period(self, x: ArrayLike) -> np.ndarray:
        """Mean return period (yr) of intensities above ``x``."""
        return return_period(self(x))

    def describe(self) -> str:
        """The curve in words, for prose (a report, a command's output): a power law or a table's size and range."""
        if self.power is not None:
            return f"the power law λ(x) = {self.power[0]:g} x^-{self.power[1]:g} per year"
        units = f" {self.units}" if self.units else ""
        extended = ", extended beyond them as power laws" if self.extrapolate else ""
        return f"a table of {self.im.size} intensities from {self.im[0]:g} to {self.im[-1]:g}{units}{extended}"

    def __repr__(self) -> str:
        if self.power is not None:
            return f"HazardCurve.power_law(k0={self.power[0]:g}, k={self.power[1]:g})"
        return (f"HazardCurve({self.im.size} points, im {self.im[0]:g}..{self.im[-1]:g}{' ' + self.units if self.units else ''}, "
                f"extrapolate={self.extrapolate})")


def bundled_curves() -> list[str]:
    """Names of the bundled hazard curves (``HazardCurve.bundled(name)``); provenance in ``data/hazard/SOURCES.md``."""
    return sorted(path.stem for path in _bundled_folder().glob("*.csv"))


def bundled_path(name: str) -> Path:
    """The file of a bundled hazard curve (``data/hazard/<name>.csv``)."""
    path = _bundled_folder() / f"{name}.csv"
    if not path.is_file():
        raise ValueError(f"name: no bundled hazard curve {name!r}; bundled: {', '.join(bundled_curves())}")
    return path


def bundled_measure(name: str) -> Measure:
    """The intensity measure of a bundled curve, from the end of its name (``_pga``, or ``_sa<T>s`` with ``p`` for the point).

    Returns
    -------
    stochpound.motions.Measure
        PGA, or PSA at the period the name gives (s) with the damping
        ``BUNDLED_DAMPING`` (0.05); every bundled curve is in ``BUNDLED_UNITS`` (g).
    """
    match = _BUNDLED_MEASURE.search(name)
    if match is None or name not in bundled_curves():
        raise ValueError(f"name: no bundled hazard curve {name!r}; bundled: {', '.join(bundled_curves())}")
    if match.group(1):
        return Measure("pga")
    return Measure("psa", float(f"{match.group(2)}.{match.group(3)}"), damping=BUNDLED_DAMPING)


def bundled_site_curves(name: str) -> list[str]:
    """The bundled curves of the site of bundled curve ``name``: those whose names differ from it only in the measure's ending (itself included),
    PGA first, then PSA by increasing period.

    E.g. ``fox_plaza_los_angeles_sa1p0s`` gives the site's PGA and PSA(0.03, 0.05, 0.1, ..., 5 s) curves.
    """
    bundled_measure(name)
    site = name[: _BUNDLED_MEASURE.search(name).start()]
    curves = [other for other in bundled_curves() if (match := _BUNDLED_MEASURE.search(other)) and other[: match.start()] == site]
    return sorted(curves, key=lambda curve: bundled_measure(curve).period or 0.0)


def _bundled_folder() -> Path:
    folder = bundled_data_dir(BUNDLED_FOLDER, "SOURCES.md")
    if folder is None:
        raise FileNotFoundError("the bundled hazard curves (data/hazard) are missing from this installation")
    return folder


def _check_positive(name: str, value: float) -> None:
    if not (np.isfinite(value) and value > 0.0):
        raise ValueError(f"{name}: must be finite and > 0, got {value!r}")
