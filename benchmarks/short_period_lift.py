"""How much long-period content lifts a motion's short-period Sa, in the bundled records and in simulated motions:
``python -m benchmarks.short_period_lift [--t-star 2.0] [--n 20] [--scenario M R_RUP MECHANISM --pool 3000 --vs30 400]``.

The lift of a motion is ln Sa(0.043 s) − ln Sa(0.043 s) of the same motion
high-passed at 1 Hz (4th-order Butterworth, zero phase): how much its content
below 1 Hz adds to its peak response at a short period (nearly its peak
acceleration). It is printed by the motion's ε at T* (against the conditional
spectrum's own model, the NGA-West2 average of the motion's scenario,
``scenario_spectrum``), beside the mean ε at 0.043 s, the median ratio of
the peak of the motion's content below 1 Hz to the peak of its content above
(low-passed and high-passed alike), and the share of motions whose two peaks
are within 1 s of each other:

- for the bundled FEMA P695 record components (far-field and near-field sets,
  each recording once), each at its own scenario (its metadata's magnitude,
  distance, Vs30 and mechanism: thrust as reverse);
- for ``n`` simulated motions (the hazard-compatible model) of each of those
  scenarios the model's range holds (seeds 100 + the record's place);
- with ``--scenario``, for ``pool`` simulated motions of one scenario (Vs30
  ``--vs30``, default 400 m/s, seed 1: a flagship's pool), whose ε at T* reaches further.

Why (docs/intensity.md, "Why the top stripe's short periods stay high"): a stripe
of high ε at T* = 2 s needs motions whose short periods are low for their
Sa(T*); if long-period content lifts the short periods more in the simulated
motions than in records, the conditional spectrum's target, fitted on
records, is out of the model's reach there.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

T_SHORT = 0.043
"""The short period (s): the flagships' shortest."""
HIGH_PASS_HZ = 1.0
"""Corner (Hz) of the high-pass filter that removes the long-period content."""
BINS = (-np.inf, 0.0, 1.0, 1.5, 2.5, np.inf)
"""Edges of the bins of ε at T*."""
MECHANISMS = {"Strike-slip": "strike_slip", "Thrust": "reverse", "Normal": "normal"}
"""The P695 metadata's fault types as the NGA-West2 models' mechanisms."""
CHUNK = 256


@dataclass(frozen=True)
class Lifts:
    """Per motion: ε at (T_SHORT, T*), the lift of ln Sa(T_SHORT) (module docstring), the ratio of the peak of its content
    below :data:`HIGH_PASS_HZ` to the peak of its content above, and the time of the first peak minus that of the second (s)."""

    epsilon: np.ndarray  # [n, 2]
    lift: np.ndarray  # [n]
    peak_ratio: np.ndarray  # [n]
    lag: np.ndarray  # [n]

    @classmethod
    def concatenate(cls, parts: list[Lifts]) -> Lifts:
        """The motions of ``parts`` together."""
        return cls(*(np.concatenate([getattr(p, name) for p in parts]) for name in ("epsilon", "lift", "peak_ratio", "lag")))


def lifts(acceleration: np.ndarray, dt: float, scenario, t_star: float) -> Lifts:
    """The lifts of motions ``acceleration`` [n, n_time] (m/s², step ``dt`` s) of ``scenario``."""
    from scipy.signal import butter, sosfiltfilt

    from stochpound.motions import DEFAULT_G, pseudo_spectra, scenario_spectrum

    periods = np.array([T_SHORT, t_star])
    high = sosfiltfilt(butter(4, HIGH_PASS_HZ, "highpass", fs=1.0 / dt, output="sos"), acceleration, axis=-1)
    low = sosfiltfilt(butter(4, HIGH_PASS_HZ, "lowpass", fs=1.0 / dt, output="sos"), acceleration, axis=-1)
    ln_sa = np.log(pseudo_spectra(acceleration, dt, periods))
    ln_high = np.log(pseudo_spectra(high, dt, periods[:1]))[:, 0]
    mean, sigma = scenario_spectrum(periods, scenario)
    ratio = np.abs(low).max(axis=-1) / np.abs(high).max(axis=-1)
    lag = (np.argmax(np.abs(low), axis=-1) - np.argmax(np.abs(high), axis=-1)) * dt
    return Lifts((ln_sa - np.log(DEFAULT_G) - mean) / sigma, ln_sa[:, 0] - ln_high, ratio, lag)


def record_scenarios() -> Iterator[tuple[np.ndarray, float, object]]:
    """Each bundled P695 record component once (by RSN and component): its acceleration (m/s²), step and scenario."""
    from stochpound.motions import DEFAULT_G, Scenario
    from stochpound.motions.records import load_suite

    seen = set()
    for suite in ("fema_p695_far_field", "fema_p695_near_field"):
        for record in load_suite(suite):
            meta = record.metadata
            if (meta["rsn"], meta["component"]) in seen:
                continue
            seen.add((meta["rsn"], meta["component"]))
            scenario = Scenario(float(meta["magnitude"]), float(meta["distance"]), float(meta["vs30"]), MECHANISMS[str(meta["fault_type"])])
            yield record.acceleration(g=DEFAULT_G), record.dt, scenario


def simulated(scenario, n: int, seed: int, t_star: float) -> Lifts:
    """The lifts of ``n`` simulated motions of ``scenario`` (the hazard-compatible model, ``seed``)."""
    from stochpound.motions import site_motions

    parts = []
    for start in range(0, n, CHUNK):
        motions = site_motions(scenario=scenario, n=n, seed=seed, realizations=list(range(start, min(n, start + CHUNK))))
        parts.append(lifts(motions["acceleration"].values, float(motions.attrs["dt"]), scenario, t_star))
    return Lifts.concatenate(parts)


def table(title: str, data: Lifts, t_star: float) -> str:
    """A markdown table of ``data`` by bins of ε at T*, and the slope of the lift on it."""
    rows = [f"**{title}** ({len(data.lift)} motions; slope of the lift on ε(T*): {np.polyfit(data.epsilon[:, 1], data.lift, 1)[0]:.3f})", "",
            f"| ε({t_star:g} s) | motions | mean ε({T_SHORT:g} s) | lift: mean | median | peak below / above 1 Hz: median | peaks within 1 s |",
            "|---|---:|---:|---:|---:|---:|---:|"]
    for low, high in zip(BINS, BINS[1:]):
        inside = (data.epsilon[:, 1] >= low) & (data.epsilon[:, 1] < high)
        if inside.any():
            rows.append(f"| [{low:g}, {high:g}) | {int(inside.sum())} | {data.epsilon[inside, 0].mean():+.2f} | {data.lift[inside].mean():.3f} | "
                        f"{np.median(data.lift[inside]):.3f} | {np.median(data.peak_ratio[inside]):.2f} | {np.mean(np.abs(data.lag[inside]) < 1.0):.2f} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    """Print the tables (module docstring)."""
    from stochpound import StochpoundError
    from stochpound.motions import Scenario

    parser = argparse.ArgumentParser(prog="python -m benchmarks.short_period_lift", description=__doc__.splitlines()[0])
    parser.add_argument("--t-star", type=float, default=2.0)
    parser.add_argument("--n", type=int, default=20, help="simulated motions per record's scenario")
    parser.add_argument("--limit", type=int, default=None, help="the first LIMIT record components only")
    parser.add_argument("--scenario", nargs=3, metavar=("M", "R_RUP", "MECHANISM"), default=None)
    parser.add_argument("--pool", type=int, default=3000, help="simulated motions of --scenario")
    parser.add_argument("--vs30", type=float, default=400.0, help="Vs30 of --scenario, m/s")
    a = parser.parse_args(argv)
    recorded, modelled, outside = [], [], 0
    for place, (acceleration, dt, scenario) in enumerate(record_scenarios()):
        if a.limit is not None and place >= a.limit:
            break
        recorded.append(lifts(acceleration[None, :], dt, scenario, a.t_star))
        try:
            modelled.append(simulated(scenario, a.n, 100 + place, a.t_star))
        except StochpoundError:  # a scenario outside the model's calibrated range
            outside += 1
    print(table("Records (FEMA P695)", Lifts.concatenate(recorded), a.t_star), "\n")
    print(table(f"Simulated, {a.n} of each record's scenario ({outside} scenarios outside the model's range left out)",
                Lifts.concatenate(modelled), a.t_star))
    if a.scenario is not None:
        scenario = Scenario(float(a.scenario[0]), float(a.scenario[1]), a.vs30, a.scenario[2])
        print("\n" + table(f"Simulated, M {scenario.magnitude:g} at {scenario.distance_km:g} km, {scenario.mechanism}, Vs30 {a.vs30:g} m/s, seed 1",
                           simulated(scenario, a.pool, 1, a.t_star), a.t_star))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
