"""Regenerate the figure of docs/intensity.md: the FEMA P695 far-field suite scaled to PSA(1 s) = 0.5 g.

Usage (from the repository root)::

    .venv/bin/python docs/figures/make_intensity_figure.py

Every one of the suite's 44 as-recorded motions is scaled so that its own
PSA at T = 1 s (5 % damping) is 0.5 g (the stripe of that level); the
figure draws their spectra, the suite's median and its 16 and 84 %
percentiles, and prints the range of the scale factors. Deterministic.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from stochpound.motions import response_spectrum  # noqa: E402
from stochpound.motions.records import load_suite  # noqa: E402

SUITE = "fema_p695_far_field"
G = 9.81
ANCHOR, LEVEL = 1.0, 0.5  # s, g
PERIODS = np.geomspace(0.05, 5.0, 80)
OUT = Path(__file__).with_name("intensity_suite_spectra.png")


def main() -> None:
    motions = load_suite(SUITE)
    spectra, scales = [], []
    for record in motions:
        psa = response_spectrum(record, None, np.append(PERIODS, ANCHOR), g=G).psa.values / G
        scale = LEVEL / psa[-1]
        scales.append(scale)
        spectra.append(scale * psa[:-1])
    spectra = np.array(spectra)
    fig, ax = plt.subplots(figsize=(6.5, 4.2), layout="constrained")
    for row in spectra:
        ax.loglog(PERIODS, row, lw=0.5, color="0.75")
    low, median, high = np.percentile(spectra, [16, 50, 84], axis=0)
    ax.loglog(PERIODS, median, "k-", lw=1.8, label="median")
    ax.loglog(PERIODS, low, "k--", lw=1.0, label="16 % and 84 %")
    ax.loglog(PERIODS, high, "k--", lw=1.0)
    ax.plot([ANCHOR], [LEVEL], "o", color="tab:red", label=f"PSA({ANCHOR:g} s) = {LEVEL:g} g")
    ax.set_xlabel("period T (s)")
    ax.set_ylabel("PSA (g), 5 % damping")
    ax.set_title(f"{SUITE}: {len(motions)} motions scaled to the stripe PSA({ANCHOR:g} s) = {LEVEL:g} g", fontsize=9)
    ax.grid(True, which="both", lw=0.3, color="0.85")
    ax.legend(fontsize=8)
    fig.savefig(OUT, dpi=140)
    print(f"wrote {OUT}; scale factors {min(scales):.2f}-{max(scales):.2f} (median {np.median(scales):.2f})")


if __name__ == "__main__":
    main()
