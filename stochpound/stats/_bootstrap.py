"""Resampling the motions of an ensemble: bootstrap and jackknife weights, and bias-corrected accelerated intervals.

Record-to-record variability is sampled by the motions (records), so the
motions, not the runs, are resampled: a resample is a vector of how many
times each motion appears (weights), applied to every stripe, threshold and
configuration at once, and every estimate is refitted with those weights.

Intervals are Efron's (1987) bias-corrected and accelerated (BCa)
percentiles: the percentile levels are shifted by the bias correction
z0 = Φ⁻¹(share of resamples below the estimate) and the acceleration
a = Σ d³ / (6 (Σ d²)^1.5) of the jackknife (leave-one-motion-out)
estimates, d = mean − estimate_i. BCa corrects the percentile interval's
under-coverage for biased, skewed estimators such as a log-standard
deviation; where z0 or a cannot be computed (e.g. a degenerate fit) the
plain percentile interval is used.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.stats._earthquakes import earthquake_identities


def bootstrap_weights(motions: int, resamples: int, seed: int | Sequence[int], clusters: Sequence[object] | None = None) -> np.ndarray:
    """How many times each motion appears in each resample with replacement: the one resampler of the toolkit.

    Without ``clusters`` each resample draws ``motions`` indices uniformly
    with replacement from ``numpy.random.default_rng(seed)`` and counts them.
    With ``clusters`` (a label per motion, e.g. its earthquake) the clusters
    are resampled instead: each resample draws as many clusters as there are,
    with replacement, and every motion of a drawn cluster appears as often as
    its cluster was drawn (the cluster bootstrap of Davison & Hinkley 1997,
    §3.8). Motions of one event share its source and path, so their responses
    are correlated; resampling them as if independent makes intervals too
    narrow. Singleton clusters in motion order give exactly the plain
    resampler's weights. The fragility and risk bootstraps and the percentile
    bootstrap of the mean (:func:`stochpound.stats.kernels.bootstrap_mean_interval`)
    all use it.

    Parameters
    ----------
    motions : int
        Number of motions (values) resampled, at least 2.
    resamples : int
        Number of resamples, positive.
    seed : int or sequence of int
        Seed of :func:`numpy.random.default_rng`: the same seed gives the same weights.
    clusters : sequence, optional
        One hashable label per motion; motions with equal labels are resampled together.

    Returns
    -------
    numpy.ndarray
        Counts, float, shape (resamples, motions).
    """
    if not (isinstance(resamples, (int, np.integer)) and resamples > 0):
        raise ValueError(f"bootstrap: must be a positive number of resamples, got {resamples!r}")
    _require_resampling(motions, clusters)
    index, count = _cluster_index(motions, clusters)
    drawn = np.random.default_rng(seed).integers(0, count, size=(resamples, count))
    drawn_counts = np.bincount((drawn + count * np.arange(resamples)[:, None]).ravel(), minlength=resamples * count)
    return drawn_counts.reshape(resamples, count)[:, index].astype(np.float64)


def resampling_obstacle(motions: int, clusters: Sequence[object] | None = None) -> str:
    """Why the motions cannot be resampled, in words; "" when they can (at least 2 motions, and 2 clusters where clustered).

    Record-to-record variability is estimated from the spread between
    independent draws: with one motion, or with every motion in one cluster
    (one earthquake, whose motions are drawn together), every resample is
    the sample itself, so no interval is estimable (a zero-width one would
    claim a certainty the motions do not give). The risk chain then gives
    its estimates without intervals and says why (this sentence).

    Parameters
    ----------
    motions : int
        Number of motions.
    clusters : sequence, optional
        One label per motion (:func:`motion_clusters`: ``event <name>``,
        ``station <name>`` or ``motion <i>``); None: every motion its own.

    Returns
    -------
    str
        "" when a bootstrap can run, else the reason, e.g. "all 3 motions
        come from one earthquake (Northridge 1994), and ...".
    """
    if motions < 2:
        return "only one motion, and a single record has no record-to-record variability to resample" if motions == 1 else "no motion"
    _, count = _cluster_index(motions, clusters)
    if count > 1:
        return ""
    kind, _, name = str(next(iter(clusters))).partition(" ")  # one cluster: clusters is not None
    unit, named = {"event": ("earthquake", f" ({name})"), "station": ("station", f" ({name}, earthquake unknown)")}.get(kind, ("cluster", ""))
    every = "both" if motions == 2 else f"all {motions}"
    return (f"{every} motions come from one {unit}{named}, and the bootstrap draws the motions of one {unit} together (they are "
            f"not independent), so a single {unit} leaves nothing to resample from record to record")


def _require_resampling(motions: int, clusters: Sequence[object] | None) -> None:
    """Raise ValueError naming the field where :func:`resampling_obstacle` finds the motions cannot be resampled."""
    obstacle = resampling_obstacle(motions, clusters)
    if obstacle:
        field, fewest = ("record", f"2 motions, got {motions}") if motions < 2 else ("clusters", "2 clusters (events), got 1")
        raise ValueError(f"{field}: the bootstrap needs at least {fewest}: {obstacle}")


def jackknife_weights(motions: int, clusters: Sequence[object] | None = None) -> np.ndarray:
    """Leave-one-out weights, shape (clusters, motions): 0 for the motions of the cluster left out, 1 elsewhere.

    Without ``clusters`` every motion is its own cluster (an array
    (motions, motions), 0 on the diagonal). Like :func:`bootstrap_weights`, it needs at least 2 clusters.
    """
    _require_resampling(motions, clusters)
    index, count = _cluster_index(motions, clusters)
    return (np.arange(count)[:, None] != index[None, :]).astype(np.float64)


def motion_clusters(events: Sequence[object], stations: Sequence[object] | None = None,
                    magnitudes: Sequence[float] | None = None) -> np.ndarray | None:
    """Cluster labels of motions for :func:`bootstrap_weights`: their earthquake, or their station where the event is unknown.

    The earthquake is the event normalised across suites
    (:func:`stochpound.motions.records.earthquake_identities`: "Northridge
    1994" and "Northridge-01 1994" of the same magnitude are one cluster).

    Parameters
    ----------
    events : sequence of str
        Each motion's event, ``"<name> <year>"`` ("" where unknown).
    stations : sequence of str, optional
        Each motion's recording station, used where the event is blank.
    magnitudes : sequence of float, optional
        Each motion's moment magnitude (NaN where unknown), which the
        normalisation checks; None: only identical event names are one earthquake.

    Returns
    -------
    numpy.ndarray or None
        One label per motion; None when no motion has an event or station
        (every motion is then its own cluster).
    """
    events = earthquake_identities(events, magnitudes)
    stations = [str(s) for s in stations] if stations is not None else [""] * len(events)
    if len(stations) != len(events):
        raise ValueError(f"stations: must hold one per motion ({len(events)}), got {len(stations)}")
    labels = []
    for i, (event, station) in enumerate(zip(events, stations, strict=True)):
        labels.append(f"event {event}" if event else (f"station {station}" if station else f"motion {i}"))
    if all(label.startswith("motion ") for label in labels):
        return None
    return np.array(labels, dtype=object)


def record_clusters(data: xr.DataArray | xr.Dataset, record_dim: str = "record") -> np.ndarray | None:
    """The cluster of each motion along ``record_dim`` from a store's motion metadata: :func:`motion_clusters` of its
    ``record_event`` (and ``record_station``, ``record_magnitude``) coordinates; None where ``data`` has neither (every motion its own cluster)."""
    if "record_event" not in data.coords or record_dim not in data["record_event"].dims:
        return None
    stations = data.coords["record_station"].values if "record_station" in data.coords else None
    magnitude = data.coords.get("record_magnitude")
    magnitudes = magnitude.values if magnitude is not None and magnitude.dims == data["record_event"].dims else None
    return motion_clusters(data.coords["record_event"].values, stations, magnitudes)


def bootstrap_method(clusters: np.ndarray | None, ran: np.ndarray | None = None) -> str:
    """How the motions were resampled, in words, for results' ``method`` attributes.

    Parameters
    ----------
    clusters : numpy.ndarray or None
        Each motion's cluster (:func:`motion_clusters`); None: every motion its own.
    ran : numpy.ndarray of bool, optional
        Which motions ran (last axis: the motions; leading axes, e.g. one per
        stripe, each a sample of its own). A motion that did not run (a
        conditional-spectrum stripe runs only its chosen motions of a pool)
        adds nothing to the fits, so the sentence counts the clusters and
        motions of the runs: over all of them and, where they differ, per
        stripe. Default: every motion ran.
    """
    if clusters is None:
        return "BCa bootstrap over motions"
    labels = np.asarray(clusters, dtype=object)
    ran = np.ones((1, labels.size), dtype=bool) if ran is None else np.asarray(ran, dtype=bool).reshape(-1, labels.size)
    used = ran.any(0)
    counts = sorted({(len(set(labels[row])), int(row.sum())) for row in ran if row.any()})
    text = f"{len(set(labels[used]))} clusters of the {int(used.sum())} motions that ran"
    if used.sum() < labels.size:
        text = f"{text}, of the {labels.size} the store holds"
    if counts and counts != [(len(set(labels[used])), int(used.sum()))]:
        clusters, motions = (_span([pair[i] for pair in counts]) for i in (0, 1))
        text = f"{text}; per stripe {clusters} clusters of {motions} motions"
    return f"BCa cluster bootstrap over events ({text}; station where the event is unknown)"


def _span(values: list[int]) -> str:
    """``a`` or ``a–b``: the smallest and largest of ``values``."""
    low, high = min(values), max(values)
    return f"{low}" if low == high else f"{low}–{high}"


def _cluster_index(motions: int, clusters: Sequence[object] | None) -> tuple[np.ndarray, int]:
    """Each motion's cluster number (in order of first appearance) and the number of clusters."""
    if clusters is None:
        return np.arange(motions), motions
    labels = list(clusters)
    if len(labels) != motions:
        raise ValueError(f"clusters: must hold one label per motion ({motions}), got {len(labels)}")
    numbers: dict[object, int] = {}
    index = np.array([numbers.setdefault(label, len(numbers)) for label in labels], dtype=np.intp)
    return index, len(numbers)


def interval(samples: np.ndarray, estimate: np.ndarray, jackknife: np.ndarray | None, confidence: float) -> tuple[np.ndarray, np.ndarray]:
    """Two-sided BCa interval from bootstrap ``samples`` (last axis), falling back to percentiles.

    Parameters
    ----------
    samples : numpy.ndarray
        The estimate refitted to each resample (last axis); NaN samples are left out, ``inf`` kept.
    estimate : numpy.ndarray
        The estimate from all motions (the leading shape of ``samples``).
    jackknife : numpy.ndarray or None
        The estimate refitted without each motion (last axis); None: percentile interval.
    confidence : float
        Two-sided level, in (0, 1).

    Returns
    -------
    lower, upper : numpy.ndarray
        The bounds (the resamples' order statistics at the corrected levels).
    """
    tail = (1.0 - confidence) / 2.0
    levels = np.broadcast_to(np.array([tail, 1.0 - tail]), (*samples.shape[:-1], 2))
    if jackknife is not None:
        levels = _bca_levels(samples, np.asarray(estimate, dtype=float), jackknife, levels)
    ordered = np.sort(samples, axis=-1)  # NaN last
    count = np.count_nonzero(~np.isnan(samples), axis=-1)[..., None]
    index = np.clip(np.ceil(levels * count).astype(int) - 1, 0, np.maximum(count - 1, 0))
    bounds = np.take_along_axis(ordered, index, axis=-1)
    bounds = np.where(count > 0, bounds, np.nan)
    return bounds[..., 0], bounds[..., 1]


def _bca_levels(samples: np.ndarray, estimate: np.ndarray, jackknife: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """The BCa percentile levels (…, 2); the plain ones where z0 or the acceleration is not finite."""
    from scipy import special

    with np.errstate(invalid="ignore", divide="ignore", over="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        valid = ~np.isnan(samples)
        below = np.sum(samples < estimate[..., None], axis=-1) + 0.5 * np.sum(samples == estimate[..., None], axis=-1)
        z0 = special.ndtri(below / valid.sum(-1))
        deviation = np.nanmean(jackknife, axis=-1)[..., None] - jackknife
        acceleration = np.nansum(deviation**3, -1) / (6.0 * np.nansum(deviation**2, -1) ** 1.5)
        acceleration = np.where(np.nansum(deviation**2, -1) > 0.0, acceleration, 0.0)
        z = special.ndtri(levels)
        shifted = z0[..., None] + z
        corrected = special.ndtr(z0[..., None] + shifted / (1.0 - acceleration[..., None] * shifted))
    usable = np.isfinite(corrected) & np.isfinite(z0)[..., None] & np.isfinite(acceleration)[..., None]
    return np.where(usable, corrected, levels)
