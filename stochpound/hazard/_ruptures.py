"""A site given by its ruptures: the hazard of any measure, its exact disaggregation and the exact conditional spectrum.

A site is, at bottom, the earthquakes that can shake it: ruptures r, each
with a magnitude, its distances to the site (R_rup, R_JB, R_x), the depth
to its top Z_tor, its dip and mechanism, and an annual rate of occurrence
ν_r, at a site of Vs30 (and, where known, basin depths Z1.0 and Z2.5). The
ground-motion models of the conditional spectrum (the NGA-West2 average of
:mod:`stochpound.motions`, its ``geometry`` taking each rupture's fields)
give ln IM in each rupture as normal with mean μ_r and σ_r, untruncated as
in :func:`~stochpound.analysis.scenario_hazard`. Then, for any measure
(PGA, PSA(T), Sa_avg):

* the hazard λ(IM > x) = Σ_r ν_r Φc(ε_r(x)), ε_r(x) = (ln x − μ_r)/σ_r;
* the disaggregation at x: each rupture's share ν_r Φc(ε_r)/λ(x) of the
  exceedances (what hazard codes print), its means of M, R and ε and its
  (M, R, ε) bins, and the share of the ground motions *at* x,
  P(r | IM = x) ∝ ν_r φ(ε_r)/σ_r (the density of ln IM at ln x);
* the uniform-hazard spectrum, the PSA of every period at a rate, solved
  exactly from the sum (no table);
* the exact conditional spectrum (Lin, Harmsen, Baker & Luco 2013): ln Sa
  given IM* = x is the mixture over the ruptures of their conditional
  normals (:func:`~stochpound.motions.conditional_spectrum`, one per
  rupture) with weights P(r | IM* = x): mean Σ p_r m_r, covariance
  Σ p_r C_r (within) + Σ p_r (m_r − m)(m_r − m)ᵀ (between). Conditioning on
  IM* = x exactly calls for the shares at x, not those of IM* > x; the
  latter (what a published disaggregation gives) are available as
  ``weights="exceedance"``.

A rupture table is a CSV file (docs/intensity.md, "A site of ruptures"):
``#`` comment lines (its provenance, and ``# vs30: ...``, ``# z1p0_km: ...``,
``# z2p5_km: ...`` for the site), a header naming the columns
:data:`RUPTURE_COLUMNS` (any order, an optional ``name`` column), one row per
rupture. Bundled demonstration sites are in ``data/ruptures/``
(:func:`bundled_rupture_sites`).
"""

from __future__ import annotations

import csv
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import InitVar, dataclass, field, fields
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from stochpound._data_files import bundled_data_dir
from stochpound._errors import SiteError
from stochpound._text_files import written_or_returned
from stochpound.hazard._curve import HazardCurve
from stochpound.motions import (
    MECHANISMS,
    Measure,
    Scenario,
    check_damping,
    conditional_distribution,
    conditioning_attrs,
    conditioning_measure,
    measure_distribution,
    scenario_spectrum,
    spectrum_dataset,
)

RUPTURE_COLUMNS = ("magnitude", "distance_rup_km", "distance_jb_km", "distance_x_km", "ztor_km", "dip", "mechanism", "rate")
"""The columns of a rupture table: moment magnitude, the rupture, Joyner–Boore and R_x distances (km; R_x ≥ 0 on the
hanging wall), the depth to the top of rupture (km), the dip (degrees), the mechanism and the annual rate of occurrence (1/yr)."""
SITE_FIELDS = ("vs30", "z1p0_km", "z2p5_km")
"""The site's fields of a rupture table (its ``# key: value`` lines, or arguments): Vs30 (m/s), the depths to 1.0 and 2.5 km/s (km)."""
BUNDLED_FOLDER = "ruptures"
"""Name of the bundled folder of rupture tables (``data/ruptures/`` in the repository, with its ``SOURCES.md``)."""
EPSILON_RANGE = (-4.0, 6.0)
"""ε of a hazard table's first intensity below the weakest rupture's median and of its last above the strongest's."""
TABLE_POINTS = 401
"""Intensities of a hazard table, log-spaced."""
MAGNITUDE_EDGES = (3.5, 5.0, 5.5, 6.0, 6.5, 7.0, 7.5, 8.0, 8.5)
"""Default magnitude bins of a disaggregation."""
DISTANCE_EDGES = (0.0, 10.0, 20.0, 30.0, 50.0, 75.0, 100.0, 150.0, 200.0, 300.0)
"""Default rupture-distance bins of a disaggregation, km."""
EPSILON_EDGES = (-np.inf, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0, np.inf)
"""Default ε bins of a disaggregation (those of the USGS's disaggregations)."""
WEIGHTS = ("level", "exceedance")
"""Weights of the exact conditional spectrum's mixture: P(rupture | IM* = x), or the exceedance shares P(rupture | IM* > x)."""
_GEOMETRY = ("distance_jb_km", "distance_x_km", "ztor_km", "dip")


@dataclass(frozen=True)
class RuptureSite:
    """A site given by the ruptures that can shake it (module docstring): a frozen value, every rupture checked once, when made.

    Iterating it gives each rupture as its :class:`~stochpound.motions.Scenario` (the site's Vs30 and basin depths
    with the rupture's magnitude, distances, depth, dip and mechanism) and its annual rate of occurrence.

    Parameters
    ----------
    magnitude, distance_rup_km, distance_jb_km, distance_x_km, ztor_km, dip : tuple of float
        One per rupture: moment magnitude, distances (km; R_x ≥ 0 on the hanging wall), depth to the top of rupture (km), dip (°).
    mechanism : tuple of str
        One per rupture: ``"strike_slip"``, ``"reverse"`` or ``"normal"``.
    rate : tuple of float
        One per rupture: annual rate of occurrence ν (1/yr), > 0.
    vs30 : float
        The site's Vs30, m/s.
    z1p0_km, z2p5_km : float, optional
        The site's depths to 1.0 and 2.5 km/s, km (None: each model's estimate from Vs30).
    names : tuple of str
        A label per rupture (default: ``"r1"``, ``"r2"``, ...).
    name, source : str
        The site's name and provenance (a file's comment lines); two sites of the same ruptures are equal whatever their names.
    row_names : sequence of mapping, optional
        Per rupture, how its fields are named in an error (a rupture table's file and line); default ``ruptures[i].column``.

    Raises
    ------
    SiteError
        Naming the rupture and field: a value outside the models' range, an unknown mechanism, a rate not > 0.
    """

    magnitude: tuple[float, ...]
    distance_rup_km: tuple[float, ...]
    distance_jb_km: tuple[float, ...]
    distance_x_km: tuple[float, ...]
    ztor_km: tuple[float, ...]
    dip: tuple[float, ...]
    mechanism: tuple[str, ...]
    rate: tuple[float, ...]
    vs30: float
    z1p0_km: float | None = None
    z2p5_km: float | None = None
    names: tuple[str, ...] = ()
    name: str = field(default="", compare=False)
    source: str = field(default="", compare=False)
    row_names: InitVar[Sequence[Mapping[str, str]] | None] = None

    def __post_init__(self, row_names: Sequence[Mapping[str, str]] | None) -> None:
        count = len(self.magnitude)
        if count == 0:
            raise SiteError("ruptures: a site needs one or more ruptures")
        for column in RUPTURE_COLUMNS:
            values = getattr(self, column)
            if not isinstance(values, tuple) or len(values) != count:
                raise SiteError(f"{column}: must be a tuple of one value per rupture ({count}), got {values!r}")
        if not self.names:
            object.__setattr__(self, "names", tuple(f"r{i + 1}" for i in range(count)))
        if len(self.names) != count or len(set(self.names)) != count:
            raise SiteError(f"names: must be {count} distinct labels, one per rupture")
        spelled = row_names or [{column: f"ruptures[{i}].{column}" for column in RUPTURE_COLUMNS} for i in range(count)]
        object.__setattr__(self, "_scenarios", tuple(_rupture_scenario(self.row(i), self.site_fields(), spelled[i]) for i in range(count)))

    # ------------------------------------------------------------ construction

    @classmethod
    def from_file(cls, path: str | Path, *, vs30: float | None = None, z1p0_km: float | None = None, z2p5_km: float | None = None,
                  name: str = "") -> RuptureSite:
        """The site of a rupture table (module docstring); ``vs30``, ``z1p0_km`` and ``z2p5_km`` complete its ``#`` header lines.

        Raises
        ------
        SiteError
            One line, starting with the file's name and the line: a missing or
            unknown column, a value out of range, a site field missing or
            contradicting the file.
        """
        path = Path(path)
        return read_ruptures(path, {"vs30": vs30, "z1p0_km": z1p0_km, "z2p5_km": z2p5_km}, name or path.stem)

    @classmethod
    def bundled(cls, name: str, **site: float | None) -> RuptureSite:
        """A demonstration site shipped with stochpound (``data/ruptures/<name>.csv``; :func:`bundled_rupture_sites` lists them).

        ``site`` (``vs30``, ``z1p0_km``, ``z2p5_km``) completes the file's site fields, as for :meth:`from_file`.
        """
        return cls.from_file(bundled_rupture_path(name), **site, name=name)

    @classmethod
    def from_scenarios(cls, ruptures: Sequence[tuple[Scenario, float]], *, name: str = "", source: str = "") -> RuptureSite:
        """The site of ruptures given as (scenario, annual rate of occurrence) pairs, as iterating a site gives them back.

        The scenarios share the site's ``vs30``, ``z1p0_km`` and ``z2p5_km``; a rupture's geometry a scenario leaves
        out is the conditional spectrum's estimate (R_JB = R_rup, R_x = −R_rup, Z_tor = 0, the mechanism's dip).

        Raises
        ------
        SiteError
            No ruptures, scenarios of different sites, or as the constructor.
        """
        if not ruptures:
            raise SiteError("ruptures: a site needs one or more ruptures")
        first = ruptures[0][0]
        for index, (scenario, _) in enumerate(ruptures):
            for key in SITE_FIELDS:
                if getattr(scenario, key) != getattr(first, key):
                    raise SiteError(f"ruptures[{index}].{key}: the ruptures of a site share its {key}, got {getattr(scenario, key)!r} "
                                    f"and {getattr(first, key)!r}")
        rows = [{"distance_jb_km": s.distance_km, "distance_x_km": -s.distance_km, "ztor_km": 0.0, "dip": MECHANISMS[s.mechanism][1]}
                | {key: value for key, value in s.geometry.items() if key in _GEOMETRY} for s, _ in ruptures]
        return cls(tuple(s.magnitude for s, _ in ruptures), tuple(s.distance_km for s, _ in ruptures),
                   *(tuple(row[key] for row in rows) for key in _GEOMETRY), tuple(s.mechanism for s, _ in ruptures),
                   tuple(rate for _, rate in ruptures), first.vs30, first.z1p0_km, first.z2p5_km, name=name, source=source)

    @classmethod
    def from_entry(cls, entry: Mapping[str, Any]) -> RuptureSite:
        """The site of a canonical entry (:meth:`to_entry`), as a definition stores it."""
        return cls(**{key: tuple(entry[key]) for key in (*RUPTURE_COLUMNS, "names")},
                   **{key: entry.get(key) for key in SITE_FIELDS}, name=entry.get("name", ""), source=entry.get("source", ""))

    def to_entry(self, identity: bool = False) -> dict[str, list[float] | list[str] | float | str | None]:
        """The site as plain data (lists, numbers, strings), for a definition or JSON: every field, or with ``identity``
        those the ground motions depend on (not ``name`` and ``source``: a renamed file or a new comment changes no target)."""
        kept = [f.name for f in fields(self) if not (identity and f.name in ("name", "source"))]
        return {key: list(value) if isinstance(value := getattr(self, key), tuple) else value for key in kept}

    def to_csv(self, path: str | Path | None = None) -> str | None:
        """The site as the rupture table :meth:`from_file` reads back as the same site: ``source`` (or the name) as ``#``
        comment lines, the site fields given as ``# key: value`` lines, a header ``name`` and :data:`RUPTURE_COLUMNS`, one row
        per rupture, every number written exactly. The text, or None once written to ``path``.

        Parameters
        ----------
        path : str or Path, optional
            Where to write the rupture table; None returns its text.
        """
        lines = [f"# {line}" for line in (self.source or self.name).splitlines()]
        lines += [f"# {key}: {float(value)!r}" for key, value in self.site_fields().items() if value is not None]
        lines.append(",".join(("name", *RUPTURE_COLUMNS)))
        for index, name in enumerate(self.names):
            row = self.row(index)
            lines.append(",".join([name, *(value if isinstance(value := row[column], str) else repr(float(value)) for column in RUPTURE_COLUMNS)]))
        return written_or_returned("\n".join(lines) + "\n", path)

    # ------------------------------------------------------------ the ruptures

    def __len__(self) -> int:
        return len(self.magnitude)

    def __iter__(self) -> Iterator[tuple[Scenario, float]]:
        """Every rupture as its scenario and its annual rate of occurrence (1/yr)."""
        return zip(self._scenarios, self.rate)

    def row(self, index: int) -> dict[str, float | str]:
        """Rupture ``index`` (0-based) as a mapping of the table's columns (:data:`~stochpound.analysis.RUPTURE_COLUMNS`)."""
        return {column: getattr(self, column)[index] for column in RUPTURE_COLUMNS}

    def site_fields(self) -> dict[str, float | None]:
        """The site's ``vs30``, ``z1p0_km`` and ``z2p5_km``."""
        return {key: getattr(self, key) for key in SITE_FIELDS}

    def scenario(self, index: int) -> Scenario:
        """Rupture ``index`` (0-based) as a scenario (:func:`~stochpound.motions.conditional_spectrum`'s ``scenario=``), its geometry given."""
        return self._scenarios[index]

    def mean_scenario(self, weights: Sequence[float]) -> Scenario:
        """The ruptures summed up by ``weights`` (one per rupture, summing to 1): the scenario of the means of ``magnitude`` and
        ``distance_km`` (R_rup, km), the site's ``vs30`` and the ``mechanism`` of the largest total weight."""
        p = np.asarray(weights, dtype=float)
        by_mechanism = {mechanism: float(p[np.array(self.mechanism) == mechanism].sum()) for mechanism in MECHANISMS}
        return Scenario(float(p @ np.asarray(self.magnitude)), float(p @ np.asarray(self.distance_rup_km)), float(self.vs30),
                        max(by_mechanism, key=lambda mechanism: by_mechanism[mechanism]))

    def moments(self, measure: str, period: float | Sequence[float] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """μ_r and σ_r of ln IM (IM in g) in every rupture, from :func:`~stochpound.motions.scenario_distribution`."""
        return _moments(self, measure, _period_key(period))

    # ------------------------------------------------------------ hazard

    def contributions(self, measure: str, period: float | Sequence[float] | None, x: Any) -> np.ndarray:
        """ν_r P(IM > x | r) (1/yr) of every rupture, over ``x``'s shape then the ruptures (x in g)."""
        from scipy.special import ndtr

        return np.asarray(self.rate) * ndtr(-self.epsilon(measure, period, x))

    def epsilon(self, measure: str, period: float | Sequence[float] | None, x: Any) -> np.ndarray:
        """ε_r(x) = (ln x − μ_r)/σ_r of every rupture, over ``x``'s shape then the ruptures."""
        values = _intensities(x)
        mean, sigma = self.moments(measure, period)
        return (np.log(values)[..., None] - mean) / sigma

    def rate_of_exceedance(self, measure: str, period: float | Sequence[float] | None, x: Any) -> np.ndarray:
        """λ(IM > x) = Σ_r ν_r P(IM > x | r), 1/yr, over ``x`` (g)."""
        return self.contributions(measure, period, x).sum(axis=-1)

    def hazard_curve(self, measure: str, period: float | Sequence[float] | None = None, *, extrapolate: bool = False,
                     points: int = TABLE_POINTS) -> HazardCurve:
        """The site's hazard curve of a measure, tabulated at ``points`` intensities (g).

        The table runs from ε −4 of the weakest rupture's median to ε 6 of
        the strongest's, log-spaced; its ``source``
        names the site. The sum itself is :meth:`rate_of_exceedance`.
        """
        mean, sigma = self.moments(measure, period)
        low, high = np.min(mean + EPSILON_RANGE[0] * sigma), np.max(mean + EPSILON_RANGE[1] * sigma)
        im = np.exp(np.linspace(low, high, points))
        return HazardCurve(im, self.rate_of_exceedance(measure, period, im), extrapolate=extrapolate, measure=Measure.of(measure, period).label,
                           units="g", source=self.describe())

    def intensity_at(self, measure: str, period: float | Sequence[float] | None, rate: Any) -> np.ndarray:
        """The intensity (g) exceeded at ``rate`` (1/yr): λ(x) = rate solved exactly from the sum (no table).

        Raises
        ------
        SiteError
            A rate not > 0 or not below the site's total rate of occurrence Σ ν_r.
        """
        mean, sigma = self.moments(measure, period)
        return _solve(np.asarray(self.rate), mean, sigma, rate)

    def uniform_hazard_spectrum(self, periods: Sequence[float], return_periods: Sequence[float] = (475.0, 2475.0)) -> xr.Dataset:
        """The uniform-hazard spectrum: the 5 %-damped PSA (g) exceeded at each rate 1/T, T a return period (yr).

        Parameters
        ----------
        periods : list of float
            Periods, s (0.01–10 s; 0 for PGA).
        return_periods : list of float
            Mean return periods, yr (e.g. 475 and 2475: 10 % and 2 % in 50 years).

        Returns
        -------
        xarray.Dataset
            ``psa`` (``return_period``, ``period``), g.
        """
        grid = np.asarray(periods, dtype=float)
        years = np.asarray(return_periods, dtype=float)
        if grid.ndim != 1 or not grid.size:
            raise SiteError(f"periods: must be one or more periods in s, got {periods!r}")
        if years.ndim != 1 or not years.size or not np.all(np.isfinite(years) & (years > 0)):
            raise SiteError(f"return_periods: must be one or more return periods > 0 yr, got {return_periods!r}")
        moments = [scenario_spectrum(grid, scenario) for scenario in self._scenarios]
        mean, sigma = (np.array([m[k] for m in moments]) for k in (0, 1))
        rates = np.asarray(self.rate)
        psa = np.array([[_solve(rates, mean[:, j], sigma[:, j], 1.0 / t)[()] for j in range(grid.size)] for t in years])
        return xr.Dataset({"psa": (("return_period", "period"), psa, {"units": "g", "long_name": "5 %-damped PSA of uniform hazard (0 s: PGA)"})},
                          coords={"return_period": ("return_period", years, {"units": "yr"}), "period": ("period", grid, {"units": "s"})},
                          attrs={"site": self.describe()})

    # ------------------------------------------------------------ disaggregation

    def disaggregation(self, measure: str, period: float | Sequence[float] | None = None, *, levels: Sequence[float],
                       magnitude_edges: Sequence[float] = MAGNITUDE_EDGES, distance_edges: Sequence[float] = DISTANCE_EDGES,
                       epsilon_edges: Sequence[float] = EPSILON_EDGES) -> xr.Dataset:
        """The exact disaggregation of the hazard of a measure at every level (g).

        Returns
        -------
        xarray.Dataset
            Over ``level`` and ``rupture``: ``contribution`` ν_r P(IM > x | r)
            (1/yr), ``share`` (its fraction of ``rate``, λ(x)), ``density_share``
            P(r | IM = x), ``epsilon`` ε_r(x); over ``level``: ``rate``,
            ``mean_magnitude``, ``mean_distance_km`` (R_rup) and
            ``mean_epsilon`` weighted by ``share``; ``binned_share`` (``level``,
            ``magnitude_bin``, ``distance_bin``, ``epsilon_bin``), the shares summed
            in bins (coordinates: their lower edges, ``*_upper`` their upper
            ones; a value outside the edges counts in the nearest end bin).
        """
        x = _intensities(levels)
        if x.ndim != 1:
            raise SiteError(f"levels: must be a list of intensities > 0 (g), got {levels!r}")
        contribution = self.contributions(measure, period, x)
        rate = contribution.sum(axis=1)
        share = contribution / rate[:, None]
        epsilon = self.epsilon(measure, period, x)
        density = _level_weights(np.asarray(self.rate), epsilon, self.moments(measure, period)[1])
        magnitude, distance = np.asarray(self.magnitude), np.asarray(self.distance_rup_km)
        edges = {"magnitude": np.asarray(magnitude_edges, float), "distance": np.asarray(distance_edges, float), "epsilon": np.asarray(epsilon_edges, float)}
        for key, values in edges.items():
            if values.ndim != 1 or values.size < 2 or not np.all(np.diff(values) > 0):
                raise SiteError(f"{key}_edges: must be 2 or more increasing bin edges, got {values.tolist()}")
        binned = np.zeros((x.size, edges["magnitude"].size - 1, edges["distance"].size - 1, edges["epsilon"].size - 1))
        m_bin, r_bin = _bins(magnitude, edges["magnitude"]), _bins(distance, edges["distance"])
        for j in range(x.size):
            np.add.at(binned[j], (m_bin, r_bin, _bins(epsilon[j], edges["epsilon"])), share[j])
        per = ("level", "rupture")
        coords = {"level": ("level", x, {"units": "g"}), "rupture": ("rupture", list(self.names)),
                  "rupture_magnitude": ("rupture", magnitude), "rupture_distance_km": ("rupture", distance, {"units": "km"}),
                  "rupture_mechanism": ("rupture", np.array(self.mechanism, dtype=object)),
                  "occurrence_rate": ("rupture", np.asarray(self.rate), {"units": "1/yr"})}
        for key, values in edges.items():
            coords[f"{key}_bin"] = (f"{key}_bin", values[:-1])
            coords[f"{key}_bin_upper"] = (f"{key}_bin", values[1:])
        return xr.Dataset(
            {
                "rate": ("level", rate, {"units": "1/yr", "long_name": "annual rate of exceedance of the level"}),
                "contribution": (per, contribution, {"units": "1/yr", "long_name": "rupture's rate of exceeding the level"}),
                "share": (per, share, {"units": "1", "long_name": "rupture's share of the exceedances, P(r | IM > x)"}),
                "density_share": (per, density, {"units": "1", "long_name": "rupture's share of the motions at the level, P(r | IM = x)"}),
                "epsilon": (per, epsilon, {"units": "1", "long_name": "epsilon of the level in the rupture"}),
                "mean_magnitude": ("level", share @ magnitude, {"units": "1"}),
                "mean_distance_km": ("level", share @ distance, {"units": "km", "long_name": "mean rupture distance"}),
                "mean_epsilon": ("level", np.sum(share * epsilon, axis=1), {"units": "1"}),
                "binned_share": (("level", "magnitude_bin", "distance_bin", "epsilon_bin"), binned, {"units": "1"}),
            },
            coords=coords,
            attrs={"measure": Measure.of(measure, period).label, "site": self.describe()},
        )

    # ------------------------------------------------------------ the exact conditional spectrum

    def conditional_spectra(self, measure: str, period: float | Sequence[float] | None = None, *, levels: Sequence[float],
                            periods: Sequence[float], damping: float = 0.05, weights: str = "level") -> list[xr.Dataset]:
        """The exact conditional spectrum of every level (g): the ruptures' conditional spectra mixed by their shares.

        Parameters
        ----------
        measure, period, periods, damping
            As :func:`~stochpound.motions.conditional_spectrum`.
        levels : list of float
            The conditioning measure's levels, g.
        weights : {"level", "exceedance"}
            The mixture's weights: P(r | IM* = x) (the exact conditioning,
            default) or the disaggregation's shares P(r | IM* > x).

        Returns
        -------
        list of xarray.Dataset
            One per level, with the variables of :func:`~stochpound.motions.conditional_spectrum`
            (the unconditional ones the mixture of the ruptures' spectra by the
            same weights), ``between_sigma_ln`` (``period``: the spread of the
            ruptures' conditional means) and ``rupture_weight`` (``rupture``).
            Attributes: ``epsilon``, ``magnitude``, ``distance_km`` (R_rup): their
            means by the weights; ``mechanism``: the one of the largest weight;
            ``vs30``, ``weights``, ``ruptures``, ``site``.
        """
        check_damping(damping)
        if weights not in WEIGHTS:
            raise SiteError(f"weights: must be one of {', '.join(WEIGHTS)}, got {weights!r}")
        x = _intensities(levels)
        parts = [conditional_distribution(measure, period, x, periods, scenario) for scenario in self._scenarios]
        epsilon = np.stack([part.epsilon for part in parts], axis=1)
        sigma = np.array([part.measure_sigma_ln for part in parts])
        rates = np.asarray(self.rate)
        mixture = _level_weights(rates, epsilon, sigma) if weights == "level" else _exceedance_weights(rates, epsilon)
        return [self._mixture(parts, mixture[j], epsilon[j], j, measure, period, float(x[j]), weights) for j in range(x.size)]

    def conditional_spectrum(self, measure: str, period: float | Sequence[float] | None = None, *, level: float, periods: Sequence[float],
                             damping: float = 0.05, weights: str = "level") -> xr.Dataset:
        """The exact conditional spectrum at one ``level`` (g): :meth:`conditional_spectra` of that level."""
        return self.conditional_spectra(measure, period, levels=[level], periods=periods, damping=damping, weights=weights)[0]

    def _mixture(self, parts: list, p: np.ndarray, epsilon: np.ndarray, j: int, measure: str, period: Any, level: float,
                 weights: str) -> xr.Dataset:
        means = np.array([part.mean_ln[j] for part in parts])
        mean = p @ means
        spread = means - mean
        within = np.einsum("r,rkl->kl", p, np.array([part.covariance for part in parts]))
        between = np.einsum("r,rk,rl->kl", p, spread, spread)
        unconditional = np.array([part.unconditional_mean_ln for part in parts])
        unconditional_mean = p @ unconditional
        unconditional_var = p @ (np.array([part.unconditional_sigma_ln for part in parts]) ** 2 + (unconditional - unconditional_mean) ** 2)
        attrs = {"epsilon": float(p @ epsilon), **conditioning_attrs(conditioning_measure(measure, period), level), **self.mean_scenario(p).loose(),
                 "weights": WEIGHT_TEXT[weights], "ruptures": len(self), "site": self.name or "a site of ruptures"}
        target = spectrum_dataset(parts[0].periods, mean, within + between, unconditional_mean, np.sqrt(unconditional_var), attrs)
        target["between_sigma_ln"] = ("period", np.sqrt(np.clip(np.diag(between), 0.0, None)),
                                      {"units": "1", "long_name": "standard deviation of the ruptures' conditional mean ln Sa"})
        target["rupture_weight"] = xr.DataArray(p, dims="rupture", coords={"rupture": list(self.names)}, attrs={"units": "1"})
        return target

    # ------------------------------------------------------------ words

    def describe(self) -> str:
        """The site in words: its name, ruptures, magnitudes, distances, total rate and Vs30."""
        basins = "".join(f", {label} {value:g} km" for label, value in (("Z1.0", self.z1p0_km), ("Z2.5", self.z2p5_km)) if value is not None)
        return (f"{self.name or 'a site'} of {len(self)} rupture{'s' if len(self) > 1 else ''}, M {min(self.magnitude):g}-{max(self.magnitude):g} "
                f"at R_rup {min(self.distance_rup_km):g}-{max(self.distance_rup_km):g} km, {sum(self.rate):.4g} per year in all, "
                f"Vs30 {self.vs30:g} m/s{basins}; NGA-West2 average (pygmm)")


WEIGHT_TEXT = {"level": "P(rupture | IM* = level), proportional to rate x density of ln IM* at the level (Lin et al. 2013)",
               "exceedance": "P(rupture | IM* > level), the disaggregation's shares of the exceedances"}


@lru_cache(maxsize=64)
def _moments(site: RuptureSite, measure: str, period: Any) -> tuple[np.ndarray, np.ndarray]:
    argument = list(period) if isinstance(period, tuple) else period
    pairs = [measure_distribution(measure, argument, scenario) for scenario, _ in site]
    median, sigma = (np.array(values) for values in zip(*pairs))
    return np.log(median), sigma


def _period_key(period: float | Sequence[float] | None) -> Any:
    """``period`` hashable (a list of periods as a tuple)."""
    return tuple(float(p) for p in period) if isinstance(period, (list, tuple, np.ndarray)) else period


def _intensities(x: Any) -> np.ndarray:
    values = np.asarray(x, dtype=float)
    if values.size == 0 or not np.all(np.isfinite(values) & (values > 0)):
        raise SiteError(f"levels: intensities must be finite and > 0 (g), got {x!r}")
    return values


def _level_weights(rates: np.ndarray, epsilon: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """P(r | IM = x) ∝ ν_r φ(ε_r)/σ_r over the last axis (the ruptures), in logs (no underflow at large ε)."""
    from scipy.special import logsumexp

    log_weight = np.log(rates) - 0.5 * epsilon**2 - np.log(sigma)
    return np.exp(log_weight - logsumexp(log_weight, axis=-1, keepdims=True))


def _exceedance_weights(rates: np.ndarray, epsilon: np.ndarray) -> np.ndarray:
    """P(r | IM > x) ∝ ν_r Φc(ε_r) over the last axis, in logs."""
    from scipy.special import log_ndtr, logsumexp

    log_weight = np.log(rates) + log_ndtr(-epsilon)
    return np.exp(log_weight - logsumexp(log_weight, axis=-1, keepdims=True))


def _bins(values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The bin of every value (the end bins take what lies beyond the edges)."""
    return np.clip(np.searchsorted(edges, values, side="right") - 1, 0, edges.size - 2)


def _solve(rates: np.ndarray, mean: np.ndarray, sigma: np.ndarray, rate: Any) -> np.ndarray:
    """x with Σ_r ν_r Φc((ln x − μ_r)/σ_r) = rate, by bracketing in ln x, over ``rate``'s shape."""
    from scipy.optimize import brentq
    from scipy.special import ndtr

    target = np.asarray(rate, dtype=float)
    total = float(rates.sum())
    if not np.all(np.isfinite(target) & (target > 0) & (target < total)):
        raise SiteError(f"rate: must be > 0 and below the site's total rate of occurrence {total:.6g} per year, got {rate!r}")
    low, high = float(np.min(mean - 12.0 * sigma)), float(np.max(mean + 12.0 * sigma))

    def excess(u: float, wanted: float) -> float:
        return float(np.log(np.sum(rates * ndtr((mean - u) / sigma))) - np.log(wanted))

    return np.exp(np.vectorize(lambda wanted: brentq(excess, low, high, args=(wanted,), xtol=1e-12))(target))


def _rupture_scenario(row: Mapping[str, float | str], site: Mapping[str, float | None], names: Mapping[str, str]) -> Scenario:
    """The rupture's scenario, checked: a :class:`SiteError` naming the field (``names``) outside the models' range, or a rate not > 0."""
    rate = row["rate"]
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not np.isfinite(rate) or rate <= 0:
        raise SiteError(f"{names['rate']}: must be an annual rate of occurrence > 0 (1/yr), got {rate!r}")
    geometry = {key: row[key] for key in _GEOMETRY} | {key: site[key] for key in ("z1p0_km", "z2p5_km")}
    spelled = {"distance_km": names["distance_rup_km"], "vs30": names.get("vs30", "vs30"), **names}
    return Scenario.of(row["magnitude"], row["distance_rup_km"], site["vs30"], row["mechanism"], geometry, names=spelled)


def read_ruptures(path: Path, given: Mapping[str, float | None], name: str) -> RuptureSite:
    """The site of the rupture table at ``path``, its site fields completed (or checked) by ``given`` (module docstring)."""
    try:
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError) as error:
        raise SiteError(f"{path.name}: cannot be read ({error})") from None
    comments, stated, header, rows = [], {}, None, []
    for number, line in enumerate(lines, start=1):
        text = line.strip()
        if not text:
            continue
        if text.startswith("#"):
            comment = text.lstrip("#").strip()
            key, colon, value = comment.partition(":")
            if colon and key.strip().lower() in SITE_FIELDS:
                stated[key.strip().lower()] = _site_number(path, number, key.strip().lower(), value)
            else:
                comments.append(comment)
            continue
        cells = [cell.strip() for cell in next(csv.reader([text]))]
        if header is None:
            header = _header(path, number, cells)
            continue
        if len(cells) != len(header):
            raise SiteError(f"{path.name}, line {number}: {len(cells)} fields, the header names {len(header)}")
        rows.append((number, dict(zip(header, cells))))
    if header is None or not rows:
        raise SiteError(f"{path.name}: no ruptures (a header row naming {', '.join(RUPTURE_COLUMNS)}, then one row per rupture)")
    site = _site(path, stated, given)
    values: dict[str, list[Any]] = {column: [] for column in (*RUPTURE_COLUMNS, "names")}
    for index, (number, cells) in enumerate(rows):
        for column in RUPTURE_COLUMNS:
            values[column].append(cells[column] if column == "mechanism" else _number(path, number, column, cells[column]))
        values["names"].append(cells.get("name") or f"r{index + 1}")
    if len(set(values["names"])) != len(rows):
        raise SiteError(f"{path.name}: name: every rupture's name must be distinct")
    spelled = [{column: f"{path.name}, line {number}: {column}" for column in RUPTURE_COLUMNS} | {"vs30": f"{path.name}: vs30"} for number, _ in rows]
    return RuptureSite(**{key: tuple(column) for key, column in values.items()}, **site, name=name, source="\n".join(comments) or path.name,
                       row_names=spelled)


def _header(path: Path, number: int, cells: list[str]) -> list[str]:
    names = [cell.lower() for cell in cells]
    missing = [column for column in RUPTURE_COLUMNS if column not in names]
    unknown = [column for column in names if column not in (*RUPTURE_COLUMNS, "name")]
    if missing or unknown or len(set(names)) != len(names):
        problem = f"missing {', '.join(missing)}" if missing else f"unknown {', '.join(unknown)}" if unknown else "a repeated column"
        raise SiteError(f"{path.name}, line {number}: header: {problem}; the columns are {', '.join(RUPTURE_COLUMNS)} (any order) and an optional name")
    return names


def _number(path: Path, number: int, column: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise SiteError(f"{path.name}, line {number}: {column}: must be a number, got {text!r}") from None


def _site_number(path: Path, number: int, key: str, text: str) -> float:
    try:
        return float(text.split()[0]) if text.split() else float(text)
    except ValueError:
        raise SiteError(f"{path.name}, line {number}: {key}: must be a number, got {text.strip()!r}") from None


def _site(path: Path, stated: Mapping[str, float], given: Mapping[str, float | None]) -> dict[str, float | None]:
    """The site's fields: the file's, completed by ``given``; a given value that contradicts the file is an error naming both."""
    site: dict[str, float | None] = {}
    for key in SITE_FIELDS:
        value, in_file = given.get(key), stated.get(key)
        if value is not None and in_file is not None and not np.isclose(float(value), in_file, rtol=1e-9, atol=0.0):
            raise SiteError(f"{key}: {value!r} given, but {path.name} states {in_file:g}")
        site[key] = float(value) if value is not None else in_file
    if site["vs30"] is None:
        raise SiteError(f"vs30: not stated: give the site's Vs30 (m/s), a '# vs30: ...' line in {path.name} or the vs30 argument / [site] field")
    return site


def named_rupture_site(name: Any, base_dir: Path, given: Mapping[str, Any], where: str) -> RuptureSite:
    """The site an experiment file names (``[site]``/``[hazard]`` ``ruptures``): a rupture table's file relative to ``base_dir``, or a
    bundled site's name; ``given`` holds the table's :data:`SITE_FIELDS` stated beside it.

    Raises
    ------
    SiteError
        Starting with the field (``<where>.ruptures``, or ``<where>.vs30`` for a site field): neither a file nor a
        bundled site, a field not a number, the table's own error (its file, line and field).
    """
    try:
        for key, value in given.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise SiteError(f"{key}: must be a number, got {value!r}")
        if not isinstance(name, str):
            raise SiteError(f"must be a rupture table's file or a bundled site's name, got {name!r}")
        if (base_dir / name).is_file():
            return RuptureSite.from_file(base_dir / name, **given)
        if name in bundled_rupture_sites():
            return RuptureSite.bundled(name, **given)
        raise SiteError(f"{name!r} is neither a file nor a bundled site of ruptures (bundled: {', '.join(bundled_rupture_sites())})")
    except SiteError as error:
        message = str(error)
        raise SiteError(f"{where}.{message}" if message.startswith(SITE_FIELDS) else f"{where}.ruptures: {message}") from None


def bundled_rupture_sites() -> list[str]:
    """Names of the bundled demonstration sites of ruptures (``RuptureSite.bundled(name)``); provenance in ``data/ruptures/SOURCES.md``."""
    return sorted(path.stem for path in _bundled_folder().glob("*.csv"))


def bundled_rupture_path(name: str) -> Path:
    """The file of a bundled site of ruptures (``data/ruptures/<name>.csv``)."""
    path = _bundled_folder() / f"{name}.csv"
    if not path.is_file():
        raise SiteError(f"name: no bundled site of ruptures {name!r}; bundled: {', '.join(bundled_rupture_sites())}")
    return path


def _bundled_folder() -> Path:
    folder = bundled_data_dir(BUNDLED_FOLDER, "SOURCES.md")
    if folder is None:
        raise FileNotFoundError("the bundled sites of ruptures (data/ruptures) are missing from this installation")
    return folder
