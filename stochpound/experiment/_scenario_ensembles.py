"""Synthetic ensembles of a site's scenario: ``[synthetic.<name>] type = "scenario_motions"``.

Instead of a Kanai–Tajimi or Clough–Penzien process, an ensemble can be the
site-based stochastic motions of an earthquake scenario
(:func:`stochpound.motions.scenario_motions`: the model of
:func:`stochpound.motions.site_motions`, Rezaeian & Der Kiureghian 2010
calibrated to the NGA-West2 models; docs/motions.md)::

    [synthetic.scenario]
    type = "scenario_motions"
    magnitude = 7.0          # 5.5-8
    distance_km = 20.0       # rupture distance, 5-100 km
    vs30 = 400.0             # m/s, 200-1100
    mechanism = "strike_slip"
    count = 500
    seed = 1
    # start = 0; dt = 0.01 (s, <= 0.02); duration (s); model = "hazard_compatible" | "rezaeian_2010"

Realization i depends on (seed, i) and the window alone. Without
``duration`` the window is the one ``site_motions(..., n=start + count,
seed=seed, dt=dt)`` chooses (every motion's modulation delivers 99.9 % of
its Arias intensity, plus the high-pass filter's tail), resolved here once
and written into the definition with the model's calibration: the store
keeps what regenerates every motion, and realization i is then motion i of
that ``site_motions`` call, bit for bit.
"""

from __future__ import annotations

from stochpound._errors import SiteError
from stochpound.store import MotionSource, TomlTable

SCENARIO_FIELDS = ("magnitude", "distance_km", "vs30", "mechanism")
"""The scenario's fields, required."""
DEFAULT_DT = 0.01
"""Time step of the motions when the table gives none, s."""
DEFAULT_MODEL = "hazard_compatible"
"""The site-motion model when the table gives none."""


def scenario_source(label: str, table: TomlTable, max_realizations: int) -> MotionSource:
    """The motion source of a ``[synthetic.<name>]`` table of ``type = "scenario_motions"``, checked, its window resolved.

    Parameters
    ----------
    label : str
        The ensemble's name (its label on ``record``).
    table : TomlTable
        The table.
    max_realizations : int
        The most realizations an ensemble may have.

    Raises
    ------
    SceneError
        Naming the field (``synthetic.<name>.magnitude: must be within 5.5-8
        (the site-motion model's calibrated range), got 9.0``): an unknown or
        missing field, a value out of its range, a calibration not the model's.
    """
    from stochpound.motions import site_motions, stated_calibration

    if "realization" in table:
        raise table.error("realization", "not used here (realizations start .. start + count - 1 are run)")
    table.reject_unknown({"type", *SCENARIO_FIELDS, "count", "start", "seed", "dt", "duration", "model", "calibration"})
    count = table.integer("count", low=1, high=max_realizations, meaning="the number of realizations")
    start = table.integer("start", 0, low=0)
    seed = table.integer("seed", low=0, meaning="the seed: realization i depends on (seed, i) and the window only")
    missing = [key for key in SCENARIO_FIELDS if key not in table]
    if missing:
        raise table.error(missing[0], "missing (the scenario: magnitude, distance_km, vs30, mechanism)")
    scenario = {key: table.raw(key) for key in SCENARIO_FIELDS}
    dt = table.number("dt", DEFAULT_DT, low=0.0, low_open=True, high=0.02)
    model = table.string("model", DEFAULT_MODEL)
    duration = table.raw("duration")
    try:
        calibration = stated_calibration(model, table.raw("calibration", None))
        first = site_motions(**scenario, n=start + count, seed=seed, dt=dt, duration=duration, model=model, realizations=[start])
    except SiteError as error:
        key, _, problem = str(error).partition(": ")
        raise table.error(key, problem) from None
    window = duration if duration is not None else round(float(first["time"].values[-1]), 9)
    entry = {"type": "scenario_motions", **scenario, "seed": seed, "dt": dt, "duration": window, "model": model, "calibration": calibration}
    return MotionSource(label, "synthetic", table.name, entry, start, count)
