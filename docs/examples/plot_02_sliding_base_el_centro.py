"""
A building on a sliding base under El Centro
============================================

The reference study's Building 1 (two storeys) on a flat sliding base with
Coulomb friction, under the first 20 s of the El Centro 1940 record as the
study used it. The base slides whenever the inertia forces exceed the
friction force μ·W, which caps the forces the superstructure receives: the
lower μ, the more the base slides and the less the storeys deform. The
fixed-base building (μ = ∞: no base at all) is the reference.
"""

# %%
# One scene per friction coefficient, from the same dictionary. The record
# is bundled with stochpound (``stochpound records list`` names them all).
import matplotlib.pyplot as plt

import stochpound

building = {
    "name": "B1",
    "mass": [26268.0, 17512.0],  # kg, floor 1 upwards
    "stiffness": [24516800.0, 17512000.0],  # N/m
    "damping": [23634.2, 16881.57],  # N s/m (1 % in mode 1)
}
motion = {"record": "el_centro_1940_study", "duration": 20.0}

runs = {}
for mu in (0.05, 0.1, 0.2, float("inf")):
    base = {} if mu == float("inf") else {"base": {"mass": 13134.0, "mu": mu}}
    scene = stochpound.scene_from_dict({"g": 9.814, "building": [building | base], "motion": motion})
    runs[mu] = stochpound.simulate(scene)

# %%
# The top floor's deformation (its displacement relative to the base) and the
# base's sliding displacement.
fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5.5))
for mu, run in runs.items():
    label = "fixed base" if mu == float("inf") else f"μ = {mu}"
    u = run.relative_displacement.sel(building="B1", floor=2)
    top.plot(run.time, 100 * u, lw=0.8, label=label)
    if mu != float("inf"):
        bottom.plot(run.time, 100 * run.sliding_displacement.sel(building="B1"), lw=1, label=label)
top.set_ylabel("top floor relative to base (cm)")
top.legend(ncol=4, fontsize="small", loc="upper right")
bottom.set_ylabel("base sliding (cm)")
bottom.set_xlabel("time (s)")
fig.tight_layout()

# %%
# Peaks over the record: storey deformation falls with μ while the sliding
# grows. The energy balance tells where the input went: into friction at the
# base or into the storeys' damping.
for mu, run in runs.items():
    u = float(abs(run.relative_displacement.sel(building="B1", floor=2)).max())
    s = float(abs(run.sliding_displacement.sel(building="B1")).max())
    friction = float(run.energy_friction[-1]) / float(run.energy_input[-1])
    print(f"mu = {mu:<5}  peak top floor {100 * u:5.2f} cm   peak sliding {100 * s:5.2f} cm   friction share of the input {friction:4.0%}")
