"""Regenerate the figures of docs/motions.md and docs/records.md (and time the generator).

Usage (from the repository root)::

    .venv/bin/python docs/figures/make_motion_figures.py           # figures
    .venv/bin/python docs/figures/make_motion_figures.py --timing  # also time 1000 x 30 s at dt = 0.01 s

Every figure is deterministic (fixed seeds).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy import signal  # noqa: E402

from stochpound import motions  # noqa: E402
from stochpound.motions.records import load_record  # noqa: E402
from stochpound.studies.agarwal2004 import STUDY_G  # noqa: E402

HERE = Path(__file__).resolve().parent


def realization_figure() -> Path:
    """One Kanai–Tajimi realization (firm soil, Jennings envelope, expected PGA 3 m/s²)."""
    firm = motions.soil_preset("firm")
    a = motions.kanai_tajimi(1, 20.0, 0.01, **firm.kanai_tajimi(), pga=3.0, envelope="jennings", seed=1)
    envelope = motions.make_envelope("jennings", 20.0)
    t = a.time.values
    fig, ax = plt.subplots(figsize=(8.0, 3.0), layout="constrained")
    ax.plot(t, a.values[0], lw=0.6, color="k", label="realization 0 (seed 1)")
    sigma = a.attrs["sigma"]
    for sign in (1, -1):
        ax.plot(t, sign * 3 * sigma * envelope(t), color="tab:red", lw=1.0, ls="--", label="±3σ e(t)" if sign > 0 else None)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("ground acceleration (m/s²)")
    ax.set_title("Kanai–Tajimi, firm soil (ω_g = 15 rad/s, ζ_g = 0.6), Jennings envelope, expected PGA 3 m/s²", fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    return _save(fig, "motion_realization.png")


def psd_figure() -> Path:
    """Welch PSD of stationary ensembles against the target S and the sampled-process PSD S_d."""
    firm = motions.soil_preset("firm")
    dt, n_seg, k = 0.01, 8192, 200
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.6), layout="constrained", sharey=True)
    for ax, (name, generator, params, model) in zip(
        axes,
        [
            ("Kanai–Tajimi", motions.kanai_tajimi, firm.kanai_tajimi(), motions.kanai_tajimi_model(**firm.kanai_tajimi(), S0=1.0)),
            ("Clough–Penzien", motions.clough_penzien, firm.clough_penzien(), motions.clough_penzien_model(**firm.clough_penzien(), S0=1.0)),
        ],
    ):
        for method, color in (("spectral", "tab:blue"), ("filter", "tab:orange")):
            a = generator(k, (n_seg - 1) * dt, dt, **params, S0=1.0, seed=2, method=method).values
            f, p = signal.welch(a, fs=1 / dt, window="hann", nperseg=n_seg, noverlap=0, detrend=False, axis=-1)
            ax.loglog(2 * np.pi * f[1:], p.mean(axis=0)[1:] / (4 * np.pi), lw=0.7, color=color, label=f"ensemble ({method}, {k} × {n_seg * dt:.0f} s)")
        w = np.geomspace(0.05, np.pi / dt, 600)
        ax.loglog(w, model.psd(w), color="k", lw=1.2, label="target S(ω)")
        ax.loglog(w, model.sampled_psd(w, dt), color="k", lw=1.0, ls=":", label="sampled-process PSD S_d(ω)")
        ax.axvspan(0.5, 50.0, color="0.92", zorder=0)
        ax.set_xlim(0.05, np.pi / dt)
        ax.set_ylim(1e-4, 3.0)
        ax.set_xlabel("ω (rad/s)")
        ax.set_title(f"{name}, firm soil, S0 = 1 m²/s³, dt = {dt} s", fontsize=9)
    axes[0].set_ylabel("two-sided PSD ((m/s²)²/(rad/s))")
    axes[1].legend(fontsize=7, loc="lower center")
    return _save(fig, "motion_psd.png")


def envelope_figure() -> Path:
    """The named envelopes with their default parameters for a 20 s motion."""
    t = np.linspace(0.0, 20.0, 2001)
    fig, ax = plt.subplots(figsize=(6.5, 3.0), layout="constrained")
    for name in ("jennings", "trapezoidal", "saragoni_hart"):
        shape = motions.make_envelope(name, 20.0)
        label = "jennings / amin_ang" if name == "jennings" else name
        ax.plot(t, shape(t), label=f"{label}: " + ", ".join(f"{k}={v:.3g}" for k, v in shape.parameters().items()))
    ax.set_xlabel("time (s)")
    ax.set_ylabel("e(t)")
    ax.set_title("Envelopes, default parameters for duration D = 20 s", fontsize=9)
    ax.legend(fontsize=7)
    return _save(fig, "motion_envelopes.png")


def records_figure() -> Path:
    """The four records of the study as bundled (Figure 3.4 of the study), in g."""
    names = ["mexico_city_1985_study", "el_centro_1940_study", "loma_prieta_1989_substitute", "northridge_1994_substitute"]
    fig, axes = plt.subplots(len(names), 1, figsize=(8.0, 8.0), layout="constrained")
    for ax, name in zip(axes, names):
        record = load_record(name)
        ax.plot(record.time, record.acceleration(STUDY_G) / STUDY_G, lw=0.5, color="k")
        label = name + ("   (SUBSTITUTE, not the study's record)" if "SUBSTITUTE" in record.provenance else "")
        ax.set_title(label, fontsize=9)
        ax.set_ylabel("a (g)")
    axes[-1].set_xlabel("time (s)")
    return _save(fig, "records_study.png")


def measure_speed(repeats: int = 3) -> None:
    """Print the best of ``repeats`` timings of 1000 realizations of 30 s at dt = 0.01 s."""
    firm = motions.soil_preset("firm")
    cases = [
        ("kanai_tajimi", "spectral", lambda m: motions.kanai_tajimi(1000, 30.0, 0.01, **firm.kanai_tajimi(), S0=1.0, method=m)),
        ("kanai_tajimi", "filter", lambda m: motions.kanai_tajimi(1000, 30.0, 0.01, **firm.kanai_tajimi(), S0=1.0, method=m)),
        ("clough_penzien", "spectral", lambda m: motions.clough_penzien(1000, 30.0, 0.01, **firm.clough_penzien(), S0=1.0, method=m)),
        ("clough_penzien", "filter", lambda m: motions.clough_penzien(1000, 30.0, 0.01, **firm.clough_penzien(), S0=1.0, method=m)),
    ]
    for model, method, run in cases:
        best = float("inf")
        for _ in range(repeats):
            start = time.perf_counter()
            run(method)
            best = min(best, time.perf_counter() - start)
        print(f"{model:15s} {method:9s} 1000 x 3001 samples: {best:.3f} s")


def _save(fig, name: str) -> Path:
    path = HERE / name
    fig.savefig(path, dpi=130)
    plt.close(fig)
    print(f"wrote {path.relative_to(HERE.parent.parent)}")
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timing", action="store_true", help="also time the generator")
    args = parser.parse_args()
    realization_figure()
    psd_figure()
    envelope_figure()
    records_figure()
    if args.timing:
        measure_speed()


if __name__ == "__main__":
    main()
