"""
From intensity stripes to the risk-targeted gap
===============================================

The risk chain in three steps on a tiny store: the study's Building 1 on a
fixed base beside its fixed-base neighbour, contact-free (``gap = inf``),
under eight motions of the FEMA P695 far-field suite scaled to four stripes
of PSA(2 s), with the bundled Fox Plaza (Los Angeles) hazard curve carried
in the store. Every gap's pounding follows from the peak closures of the
contact-free runs (the gap identity, docs/separation.md):

1. **stripes**: the experiment's runs, one per motion and stripe;
2. **fragility**: P(pounding | IM) at every gap of a grid, a lognormal
   fitted to the stripes' counts;
3. **the risk-targeted gap** ``g*``: the gap at which pounding is as rare as the target (10 % and 2 %
   in 50 years), from the fragility and the site's hazard.

Eight motions and four stripes keep this page fast; the flagship
experiments (``experiments/risk/``) select 20 motions per stripe from both
FEMA P695 sets by conditional spectrum, for yielding buildings.
"""

# %%
# The experiment: the study's elastic Building 1 beside its stiff neighbour,
# both on fixed bases (the bundled scene ``elastic_pair``, docs/scene-files.md,
# its neighbour's masses halved), stripes of PSA(2 s) with the bundled hazard of that
# measure, eight motions cut to their first 10 s and four stripes.
import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import stochpound
from stochpound import experiment
from stochpound.risk import Fragility, contact_free_closure, store_risk

records = "".join(f'[[records]]\nrecord = "fema_p695_far_field/{name}"\nduration = 10.0\n\n'
                  for name in ("01a", "03b", "05a", "07b", "10a", "12a", "14b", "19a"))
text = f"""
[experiment]
name = "stripes_gallery"
studied = "B1"

[scene]
bundled = "elastic_pair"                 # the study's Building 1 and an equal neighbour, fixed bases, 5 % damping

[scene.building.B2]                      # the stiff neighbour: the same frame, masses x 0.5
mass = [13134.0, 8756.0]                 # kg, floor 1 upwards

[grid]
gap = [inf]                              # contact-free: every gap from the peak closures

{records}
[intensity]
measure = "psa"
period = 2.0                             # s
levels = [0.2, 0.4329, 0.762, 1.143]     # g: 0.4329 and 0.762 are the 10 % and 2 % in 50 yr intensities
method = "stripes"

[hazard]
bundled = "fox_plaza_los_angeles_sa2p0s"
"""

folder = Path(tempfile.mkdtemp())
(folder / "stripes.toml").write_text(text)
report = experiment.run_experiment(experiment.load_experiment(folder / "stripes.toml"), workers=0, progress=False)
ds = stochpound.open_store(report.store)
print(f"{report.done} runs: {ds.sizes['record']} motions x {ds.sizes['intensity']} stripes, each for the pair and for Building 1 alone (the fixed-base reference)")

# %%
# **1. Stripes.** The largest contact-free closure of every run (m): the
# gap below which that run pounds.
closure = contact_free_closure(ds)
print((100 * closure).squeeze(drop=True).round(2).to_pandas())

# %%
# **2 and 3. Fragility, risk and the risk-targeted gap.** ``store_risk`` fits the fragility at
# every gap of a grid over the closures, integrates it with the stored
# hazard curve into the mean annual frequency of pounding λ_P(g), and reads
# ``g*`` off it, with bootstrap intervals over the motions. With eight motions
# the intervals are wide: ``g*`` is driven by the intensities above the
# stripes, where the fitted lognormal extrapolates.
risk = store_risk(ds, bootstrap=200)
print(risk.to_frame())

# %%
# The fragility at three gaps, with the stripes' observed fractions, and
# the risk curve with the targets' ``g*``.
fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.6))
im = np.linspace(0.01, 1.5, 200)
gaps = risk.fragility["gap"].values
for gap in gaps[[len(gaps) // 4, len(gaps) // 2, 3 * len(gaps) // 4]]:
    fit = risk.fragility.sel(gap=gap).squeeze(drop=True)
    line, = left.plot(im, Fragility(float(fit.theta), float(fit.beta))(im), label=f"gap {100 * gap:.1f} cm")
    left.plot(fit["intensity"], fit["probability"], "o", color=line.get_color())
left.set_xlabel("PSA(2 s) (g)")
left.set_ylabel("P(pounding | IM)")
left.legend()
maf = risk.curve["maf"].squeeze(drop=True)
right.loglog(100 * maf["gap"], maf, color="0.7", label="λ_P(g), at every gap")
right.loglog(100 * maf["gap"], risk.non_increasing_maf().squeeze(drop=True), "k-", label="non-increasing: g* is read here")
for target in risk.separation["target"].values:
    gstar = float(risk.separation["separation"].sel(target=target).squeeze())
    right.axvline(100 * gstar, ls="--", label=f"g* for {100 * target:g} % in 50 yr: {100 * gstar:.1f} cm")
right.set_ylim(1e-5, 1.0)
right.set_xlabel("gap (cm)")
right.set_ylabel("mean annual frequency of pounding (1/yr)")
right.legend(fontsize="small")
fig.tight_layout()
plt.show()

ds.close()
shutil.rmtree(folder)
