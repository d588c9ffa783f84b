"""Why a high stripe misses at short periods: ``python -m benchmarks.pool_shapes M R_RUP MECHANISM T_STAR [--n 3000] [--beyond 2.0]``.

Simulates ``n`` motions of the scenario (Vs30 400 m/s, seed 1, the
hazard-compatible model: a flagship's pool of simulated motions), takes
their ε at short periods and at T* against the conditional spectrum's own
model (the NGA-West2 average, ``scenario_spectrum``), and prints the
correlation of ε(T) with ε(T*) beside Baker & Jayaram's (2008), and, for the
motions of ε* ≥ ``beyond``, the mean and standard deviation of their ε(T)
beside what Baker–Jayaram's conditional normal expects at their mean ε*
(ρ ε* and √(1 − ρ²)). A pool whose short periods follow ε* more closely
than Baker–Jayaram carries, at high ε, too high and too narrow a short-period
spectrum: the conditional spectrum's stripes then miss there however large
the pool, unless it holds the tail of that tail.
"""

from __future__ import annotations

import argparse

import numpy as np

PERIODS = (0.043, 0.06, 0.1, 0.2, 0.5)
"""The periods (s) compared with T*: the flagships' shortest."""
CHUNK = 256


def main(argv: list[str] | None = None) -> int:
    """Print the comparison (module docstring)."""
    from pygmm.baker_jayaram_2008 import calc_correls

    from stochpound.motions import Scenario, pseudo_spectra, scenario_spectrum, site_motions

    parser = argparse.ArgumentParser(prog="python -m benchmarks.pool_shapes", description=__doc__.splitlines()[0])
    parser.add_argument("magnitude", type=float)
    parser.add_argument("distance_km", type=float)
    parser.add_argument("mechanism")
    parser.add_argument("t_star", type=float)
    parser.add_argument("--n", type=int, default=3000)
    parser.add_argument("--beyond", type=float, default=2.0)
    a = parser.parse_args(argv)
    periods = np.array([*PERIODS, a.t_star])
    scenario = Scenario(a.magnitude, a.distance_km, 400.0, a.mechanism)
    chunks = [site_motions(scenario=scenario, n=a.n, seed=1, realizations=list(range(start, min(a.n, start + CHUNK))))["acceleration"].values
              for start in range(0, a.n, CHUNK)]
    ln_sa = np.vstack([np.log(pseudo_spectra(chunk, 0.01, periods) / 9.81) for chunk in chunks])
    mean, sigma = scenario_spectrum(periods, scenario)
    epsilon = (ln_sa - mean) / sigma
    star = epsilon[:, -1]
    high = star >= a.beyond
    print(f"M {a.magnitude} at {a.distance_km} km, {a.mechanism}, T* = {a.t_star} s: {a.n} motions, {int(high.sum())} of ε* >= {a.beyond} "
          f"(their mean ε* {star[high].mean():.2f})")
    print("| T (s) | ρ simulated | ρ Baker–Jayaram | mean ε, ε* ≥ beyond | BJ: ρ ε* | std ε | BJ: √(1 − ρ²) |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for i, period in enumerate(PERIODS):
        rho = float(calc_correls(np.array([period]), a.t_star)[0])
        print(f"| {period:g} | {np.corrcoef(epsilon[:, i], star)[0, 1]:.2f} | {rho:.2f} | {epsilon[high, i].mean():+.2f} | "
              f"{rho * star[high].mean():+.2f} | {epsilon[high, i].std():.2f} | {np.sqrt(1 - rho**2):.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
