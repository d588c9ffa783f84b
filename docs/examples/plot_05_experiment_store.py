"""
A small experiment and its store
================================

An experiment runs a grid of scenes under a set of ground motions and
writes every case into one netCDF store, which xarray opens with the grid's
axes as dimensions. This one takes the scene of the getting-started page,
the reference study's Building 1 on a sliding base next to its flexible
fixed-base neighbour, and runs it with μ = 0.1, 0.2 or a fixed base (μ = ∞)
at five gaps, under the first 20 s of El Centro: 15 cases, plus the
building alone on a fixed base as the reference.

``stochpound experiment run FILE.toml`` does the same on a dask cluster;
here the cases run in this process (``workers=0``), in a temporary folder.
"""

# %%
# The experiment file: a base scene, the grid, the motions and what to keep.
import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import stochpound
from stochpound import experiment

# The base scene is the repository's scene file of the getting-started page
# (this script runs in ``docs/examples``); the grid overrides its gaps and
# the friction coefficient of B1's base.
scene_file = Path("../../experiments/scenes/study_b1_isolated_flexible.toml").resolve()

definition = f"""
[experiment]
name = "gap_and_mu"
studied = "B1"
scene = "{scene_file.as_posix()}"
""" + """
[grid]
gap = [0.005, 0.01, 0.02, 0.03, 0.04]
mu = { values = [0.1, 0.2, inf], buildings = ["B1"] }

[[records]]
name = "el_centro"
record = "el_centro_1940_study"
duration = 20.0

[output]
time_histories = ["total_displacement"]
buildings = ["B1"]
"""

folder = Path(tempfile.mkdtemp())
(folder / "gap_and_mu.toml").write_text(definition)
report = experiment.run_experiment(experiment.load_experiment(folder / "gap_and_mu.toml"), workers=0, progress=False)
print(f"{report.done} of {report.total} cases in {report.elapsed:.1f} s, store {report.store.name}")

# %%
# The store, opened lazily: summaries on the grid's dimensions, the kept
# time histories and one table of every impact of every case.
ds = stochpound.open_store(report.store)
print(dict(ds.sizes))

# %%
# Impacts and the largest impact force against the gap, for each friction
# coefficient: the selection names the grid's coordinates, and nothing is
# read from the file before ``compute``.
el_centro = ds.sel(record="el_centro", realization=0)[["impacts", "peak_impact_force"]].compute()
fig, (left, right) = plt.subplots(1, 2, figsize=(8, 3.5), sharex=True)
for mu in el_centro.mu.values:
    label = "fixed base" if mu == float("inf") else f"μ = {mu}"
    case = el_centro.sel(mu=mu)
    left.plot(100 * case.gap, case.impacts, "o-", label=label)
    right.plot(100 * case.gap, case.peak_impact_force / 1e3, "o-", label=label)
left.set_xlabel("gap (cm)")
left.set_ylabel("impacts")
right.set_xlabel("gap (cm)")
right.set_ylabel("largest impact force (kN)")
left.legend()
fig.tight_layout()

# %%
# The impact table is one row per impact with the case's coordinates
# (``impact_gap``, ``impact_mu``, ...), ready for pandas.
impacts = ds[["impact_gap", "impact_mu", "impact_peak_force", "impact_in_phase"]].compute().to_dataframe()
print(impacts.groupby(["impact_mu", "impact_gap"])["impact_peak_force"].agg(["count", "max"]).round(0))
ds.close()
shutil.rmtree(folder)
