"""Regenerate the figure of docs/separation.md and print the numbers the page quotes.

Usage (from the repository root)::

    .venv/bin/python docs/figures/make_separation_figure.py

The reference study's pair (experiments/scenes/study_b1_isolated_flexible.toml:
Building 1 on a sliding base with μ = 0.2, or on a fixed base, next to the
flexible fixed-base Building 2, contacts at both floors) is run contact-free
(every gap inf) under 400 Kanai–Tajimi realizations (firm soil, Jennings
envelope, expected PGA 3.4 m/s², 20 s at dt = 0.01 s, seed 14). Deterministic.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

import stochpound  # noqa: E402
from stochpound import motions  # noqa: E402
from stochpound.analysis import contact_demands, fixed_base_cqc, pounding_curve, required_separation, rule_exceedance, separation_rules  # noqa: E402
from stochpound.model.scene import Scene  # noqa: E402
from stochpound.motions.ground import SampledMotion  # noqa: E402

HERE = Path(__file__).resolve().parent
SCENE = HERE.parent.parent / "experiments" / "scenes" / "study_b1_isolated_flexible.toml"
REALIZATIONS, DURATION, DT, SEED = 400, 20.0, 0.01, 14
TARGETS = (0.5, 0.16, 0.05)
RULE_STYLES = {"abs": "tab:red", "srss": "tab:blue", "srss_reduced": "tab:cyan", "ddc": "tab:green", "ddc_cqc": "tab:olive"}


def pairs() -> dict[str, Scene]:
    """The pair with Building 1 isolated (μ = 0.2) and fixed, contact-free."""
    isolated = stochpound.load_scene(SCENE)
    isolated = dataclasses.replace(isolated, contacts=tuple(dataclasses.replace(c, gap=math.inf) for c in isolated.contacts))
    b1, b2 = isolated.buildings
    fixed = dataclasses.replace(isolated, buildings=(dataclasses.replace(b1, base=None), b2))
    return {"both fixed": fixed, "B1 isolated, μ = 0.2": isolated}


def ensemble_demands(scene: Scene, accelerations: xr.DataArray) -> xr.Dataset:
    """contact_demands of the contact-free runs of ``scene`` under every realization."""
    demands = []
    for samples in accelerations.values:
        run = stochpound.simulate(dataclasses.replace(scene, motion=SampledMotion(DT, samples, "linear", "Kanai-Tajimi")))
        demands.append(contact_demands(run))
    return xr.concat(demands, dim="realization")


def panel(ax: plt.Axes, name: str, scene: Scene, demands: xr.Dataset) -> None:
    """Pounding curve with its band, required separations, and each rule's exceedance at its median gap."""
    cqc = fixed_base_cqc(scene)
    rules = separation_rules(demands, cqc=cqc if cqc.notnull().all() else None)
    gaps = np.linspace(0.0, 1.2 * float(demands["peak_closure"].max()), 400)
    curve = pounding_curve(demands["peak_closure"], gaps)
    ax.fill_between(100 * gaps, curve["lower"], curve["upper"], color="0.85", step="post", label="95 % Clopper–Pearson band")
    ax.step(100 * gaps, curve["probability"], where="post", color="k", lw=1.2, label="P(D ≥ g), contact-free runs")
    needed = required_separation(demands["peak_closure"], TARGETS)
    ax.errorbar(100 * needed["separation"], needed["probability"], xerr=100 * abs(needed[["lower", "upper"]].to_array() - needed["separation"]),
                fmt="s", color="tab:purple", ms=4, capsize=3, label="required separation (95 % interval)")
    exceedance = rule_exceedance(demands["peak_closure"], rules)
    print(f"\n{name}: {int(curve['realizations'])} realizations")
    print(needed[["separation", "lower", "upper"]].to_dataframe().mul(100).round(2).to_string(header=["separation (cm)", "lower (cm)", "upper (cm)"]))
    for rule in rules["rule"].values:
        row = exceedance.sel(rule=rule)
        typical = 100 * float(rules.sel(rule=rule).max("contact").median())
        bar = [[float(row["probability"] - row["lower"])], [float(row["upper"] - row["probability"])]]
        ax.errorbar([typical], [float(row["probability"])], yerr=bar, fmt="o", color=RULE_STYLES[rule], capsize=3,
                    label=f"{rule}: P = {float(row['probability']):.2f} [{float(row['lower']):.2f}, {float(row['upper']):.2f}]")
        print(f"{rule:13s} median gap {typical:5.2f} cm   P(D >= rule gap) = {float(row['probability']):.3f} [{float(row['lower']):.3f}, {float(row['upper']):.3f}]")
    ax.set_title(name, fontsize=9)
    ax.set_xlabel("gap g (cm), the same at both floors")
    ax.legend(fontsize=6.5, loc="upper right")


def main() -> None:
    firm = motions.soil_preset("firm")
    accelerations = motions.kanai_tajimi(REALIZATIONS, DURATION, DT, **firm.kanai_tajimi(), pga=3.4, envelope="jennings", seed=SEED)
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0), layout="constrained", sharex=True, sharey=True)
    for ax, (name, scene) in zip(axes, pairs().items()):
        panel(ax, name, scene, ensemble_demands(scene, accelerations))
    axes[0].set_ylabel("probability of pounding")
    fig.suptitle(f"Study pair (B2 flexible), {REALIZATIONS} Kanai–Tajimi realizations (firm soil, PGA 3.4 m/s², {DURATION:g} s); "
                 "rules at their median gap, with P(D ≥ rule's gap)", fontsize=9)
    path = HERE / "separation_pounding_curve.png"
    fig.savefig(path, dpi=130)
    print(f"\nwrote {path.relative_to(HERE.parent.parent)}")


if __name__ == "__main__":
    main()
