"""
One building, one wall, one collision
=====================================

A one-storey building is pushed toward a rigid wall 1 cm away and swings
back freely: no ground motion, only an initial velocity. The wall is a
Kelvin–Voigt impact element whose damping is set by a coefficient of
restitution r = 0.5: each impact takes energy out, so the floor comes back
slower than it went in, and hits the wall a second time more gently.
"""

# %%
# The scene, written as the dictionary a scene file would hold
# (:func:`stochpound.scene_from_dict`; the fields are those of a TOML scene
# file). The ground motion is a constant zero acceleration for 2 s, sampled
# every 5 ms.
import matplotlib.pyplot as plt

import stochpound

scene = stochpound.scene_from_dict(
    {
        "building": [
            {
                "name": "B1",
                "mass": [20000.0],  # kg
                "stiffness": [8.0e6],  # N/m: period 0.31 s
                "damping_ratio": 0.02,
                "initial": {"velocity": [0.4]},  # m/s, toward the wall
            }
        ],
        "wall": [
            # tensile = false: the wall pushes but never pulls the floor back
            {"building": "B1", "side": "right", "level": 1, "gap": 0.01, "stiffness": 4.0e8, "restitution": 0.5,
             "tensile": False}
        ],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": 2.0, "dt": 0.005},
    }
)
run = stochpound.simulate(scene)
print(run.attrs["solver"], "solver:", run.attrs["solver_choice"])

# %%
# Every impact is one row of the impact table, with its timing, its peak
# force and the closing speed at its onset, all located on the solution
# (not at the output samples).
impacts = run[["impact_start", "impact_duration", "impact_peak_force", "impact_onset_velocity"]].to_dataframe()
print(impacts.round(4))

# %%
# The floor's displacement against the wall's position, and the contact
# force. The rebound after the first impact is slower, and the floor returns
# to the wall only when the storey spring pulls it back there.
y = run.total_displacement.sel(building="B1", floor=1)
force = run.wall_force.isel(wall=0)

fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
top.plot(run.time, 100 * y, label="floor 1")
top.axhline(100 * float(run.wall_gap[0]), color="k", ls="--", label="wall")
top.set_ylabel("displacement (cm)")
top.legend(loc="lower right")
bottom.plot(run.time, force / 1e3, color="C3")
bottom.set_ylabel("wall force (kN)")
bottom.set_xlabel("time (s)")
fig.tight_layout()

# %%
# The output samples are 5 ms apart and an impact lasts about 20 ms, so the
# largest sampled force falls short of the peak; the table's located peak
# does not depend on the sampling.
print(f"located peak {float(run.impact_peak_force[0]) / 1e3:.0f} kN, largest sample {float(force.max()) / 1e3:.0f} kN")
