"""measure_efficiency: β and residual trends of candidate measures, checked against a direct computation on an IDA store."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.stats import linregress

from stochpound import open_store
from stochpound.risk import measure_efficiency, most_efficient
from tests.helpers import FIXED, risk_text, run_in_process


@pytest.fixture(scope="module")
def fixed_stores(tmp_path_factory):
    """The fixed-base pair of the flagship: stripes (contact-free) and IDA, the same eight motions."""
    folder = tmp_path_factory.mktemp("fixed")
    levels = "levels = [0.1, 0.2, 0.4, 0.8, 1.6]"
    stripes = run_in_process(folder, "stripes", risk_text(FIXED, "gap = [inf]", f'measure = "psa"\nperiod = 1.0\n{levels}'))
    ida = run_in_process(folder, "ida", risk_text(FIXED, "gap = [0.01, 0.02]", f'measure = "psa"\nperiod = 1.0\n{levels}\nmethod = "ida"', hazard=""))
    return stripes, ida


def _direct_beta(im: np.ndarray, closure: np.ndarray) -> tuple[float, float]:
    fit = linregress(np.log(im), np.log(closure))
    residual = np.log(closure) - fit.intercept - fit.slope * np.log(im)
    return float(np.sqrt(np.sum(residual**2) / (len(im) - 2))), float(fit.slope)


def test_ida_efficiency_is_the_regression_of_the_one_run_per_motion(fixed_stores) -> None:
    ida = open_store(fixed_stores[1]).load()
    stored = float(ida["spectrum_period"].values[12])
    result = measure_efficiency(ida, {"stored": stored, "one second": 1.0})
    runs = ida.isel(gap=0, realization=0)
    closure = runs["peak_contact_closure"].max("contact").values
    for name, im in (("PGA", runs["motion_pga"].values), ("PGV", runs["motion_pgv"].values),
                     (f"PSA({stored:.3g} s, stored)", runs["motion_psa"].isel(spectrum_period=12).values)):
        beta, slope = _direct_beta(im, closure)
        assert float(result["beta"].sel(response="closure", measure=name)) == pytest.approx(beta, rel=1e-10)
        assert float(result["slope"].sel(response="closure", measure=name)) == pytest.approx(slope, rel=1e-10)
    assert np.all(result["runs"].values == len(closure))
    assert np.all(np.isnan(result["trend_scale_factor"].values))  # IDA: every run at scale 1
    p = result["p_magnitude"].values
    assert np.all((p >= 0) & (p <= 1))
    best = most_efficient(result, ["PGA", "PGV"])
    assert best.item() == ("PGA" if result["beta"].sel(response="closure", measure="PGA") < result["beta"].sel(response="closure", measure="PGV") else "PGV")


def test_stripes_of_a_homogeneous_scene_give_the_conditioning_measure_a_zero_spread_per_stripe(fixed_stores) -> None:
    """Fixed bases: closure = level × D_i / IM_i, so pooled over the stripes β(PSA(1 s)) is the spread of ln(D_i / IM_i)."""
    stripes = open_store(fixed_stores[0]).load()
    result = measure_efficiency(stripes, {"one second": 1.0})
    free = stripes.sel(gap=np.inf).isel(realization=0)
    ratio = np.log(free["peak_contact_closure"].max("contact").isel(intensity=0) / stripes["intensity"].values[0]).values  # ln(D_i / IM_i) + const
    name = "PSA(1 s, one second)"
    beta = float(result["beta"].sel(response="closure", measure=name))
    n = ratio.size * stripes.sizes["intensity"]
    assert beta == pytest.approx(np.std(ratio, ddof=0) * np.sqrt(n / (n - 2)), rel=1e-9)  # the store's own measure: exact
    assert float(result["slope"].sel(response="closure", measure=name)) == pytest.approx(1.0, rel=1e-9)


def test_sa_avg_over_given_periods_is_the_regression_on_the_geometric_mean_of_those_psa(fixed_stores) -> None:
    """``sa_avg_periods``: the Sa_avg candidate over the given (stored) periods, β from the runs' geometric mean of PSA times the scale."""
    stripes = open_store(fixed_stores[0]).load()
    stored = stripes["spectrum_period"].values[[8, 12, 16]]
    result = measure_efficiency(stripes, {"one second": 1.0}, sa_avg_periods=stored)
    free = stripes.sel(gap=np.inf).isel(realization=0)
    mean = np.exp(np.log(free["motion_psa"].isel(spectrum_period=[8, 12, 16])).mean("spectrum_period"))
    im, closure = xr.broadcast(mean * free["scale_factor"], free["peak_contact_closure"].max("contact"))
    beta, slope = _direct_beta(im.values.ravel(), closure.values.ravel())
    name = f"Sa_avg({stored[0]:.3g}-{stored[-1]:.3g} s)"
    assert float(result["beta"].sel(response="closure", measure=name)) == pytest.approx(beta, rel=1e-9)
    assert float(result["slope"].sel(response="closure", measure=name)) == pytest.approx(slope, rel=1e-9)
    with pytest.raises(ValueError, match="^sa_avg_periods: must be two or more periods > 0 s"):
        measure_efficiency(stripes, {"one second": 1.0}, sa_avg_periods=[1.0])


def test_risk_cli_names_the_most_efficient_measure_the_sites_hazard_has(fixed_stores) -> None:
    from click.testing import CliRunner

    from stochpound.cli import main
    from stochpound.experiment import hazard_measures

    store = open_store(fixed_stores[0]).load()
    available = hazard_measures(store, "fox_plaza_los_angeles_sa1p0s")
    periods = (0.03, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)  # the bundled site's PSA curves
    assert available == {"PGA": None, **{f"PSA({period:g} s)": period for period in periods}}
    result = CliRunner().invoke(main, ["risk", str(fixed_stores[0]), "--hazard", "fox_plaza_los_angeles_sa1p0s", "--bootstrap", "0"])
    assert result.exit_code == 0, result.output
    efficiency = measure_efficiency(store, {f"hazard {k}": v for k, v in available.items() if v is not None})
    names = ["PGA"] + [f"PSA({v:.3g} s, hazard {k})" for k, v in available.items() if v is not None]
    best = most_efficient(efficiency, names).item()
    label = "PGA" if best == "PGA" else best.split(", hazard ")[1].rstrip(")") + ")"
    assert f"most efficient the site's hazard has: {label} (" in result.output


def test_a_configuration_s_best_measure_is_never_another_configuration_s_structure_period() -> None:
    from stochpound.experiment._measure_choice import _of_configuration

    structure = {"B1 first mode": 0.3, "B2 first mode (neighbour=flexible)": 0.8, "B2 first mode (neighbour=stiff)": 0.2}
    measures = ["PGA", "PSA(0.3 s, B1 first mode)", "PSA(0.8 s, B2 first mode (neighbour=flexible))", "PSA(0.2 s, B2 first mode (neighbour=stiff))"]
    for neighbour, other in (("stiff", "flexible"), ("flexible", "stiff")):
        row = xr.DataArray(np.zeros(4), dims="measure", coords={"measure": measures, "neighbour": neighbour})
        kept = [m for m in measures if _of_configuration(m, structure, row)]
        assert kept == [m for m in measures if f"neighbour={other}" not in m]


def test_the_report_names_the_most_efficient_measure_and_weighs_the_stores_own_against_the_estimates_noise(fixed_stores) -> None:
    """The Risk section says which measure the site's hazard has is the most efficient per configuration (the same frame as
    stochpound risk prints), and how far the store's own measure is from it against the standard error of a β."""
    import math

    from stochpound.experiment import measure_choice
    from stochpound.report.sections._risk import _measure_choice_blocks
    from stochpound.risk import store_risk

    store = open_store(fixed_stores[0]).load()
    choice = measure_choice(store, "fox_plaza_los_angeles_sa1p0s")
    risk = store_risk(store, bootstrap=0)
    text = _measure_choice_blocks("s", risk, choice)[0].text
    counts = choice["most efficient"].value_counts()
    assert "the most efficient is " + ", ".join(f"{m} in {c} of {len(choice)} configurations" for m, c in counts.items()) in text
    own = "PGA" if risk.setting.measure.kind == "pga" else f"PSA({risk.setting.measure.period:g} s)"
    assert choice.attrs["store_measure"] == own
    worst = max(float(row[own] - row[row["most efficient"]]) for _, row in choice.iterrows())
    if worst == 0.0:
        assert f"conditioned on {own}, the most efficient in every configuration" in text
    else:
        runs = risk.motions * risk.stripes
        noise = float(choice[own].max()) / math.sqrt(2.0 * (runs - 2))
        assert f"by up to {worst:.3f}: {'within' if worst <= 2 * noise else 'beyond'} twice" in text and f"≈ {noise:.3f}" in text
    assert _measure_choice_blocks("s", risk, None) == []


def test_one_motion_per_stripe_names_no_most_efficient_measure(fixed_stores) -> None:
    """Issue 48: with one motion scaled to every stripe every measure fits exactly (β ≈ 0), and the least β named a measure
    "most efficient" from round-off; now the choice, stochpound risk and the report say it cannot be judged."""
    from stochpound.cli._measure_choice import efficient_measure_lines
    from stochpound.experiment import measure_choice
    from stochpound.experiment._measure_choice import ONE_MOTION
    from stochpound.report.sections._risk import _measure_choice_blocks
    from stochpound.risk import HazardCurve, StoreRisk

    store = open_store(fixed_stores[0]).load()
    assert measure_choice(store, "fox_plaza_los_angeles_sa1p0s").attrs["unjudged"] == ""
    one = store.isel(record=[0])
    choice = measure_choice(one, "fox_plaza_los_angeles_sa1p0s")
    assert choice.attrs["unjudged"] == ONE_MOTION and ONE_MOTION.startswith("efficiency cannot be judged from one motion per stripe")
    assert (choice["most efficient"] == "").all() and (choice["best candidate"] == "").all() and choice["best β"].isna().all()
    assert float(choice[choice.attrs["hazard_measures"]].abs().max().max()) < 1e-6  # the fit is exact: β is round-off
    assert efficient_measure_lines(one, "fox_plaza_los_angeles_sa1p0s") == ["", f"Which measure: {ONE_MOTION}."]
    risk = StoreRisk(xr.Dataset(), xr.Dataset(), xr.Dataset(), None, "", HazardCurve.power_law(1e-4, 2.0), 1, "stripes", stripes=5)
    blocks = _measure_choice_blocks("s", risk, choice)
    assert len(blocks) == 1 and blocks[0].text == f"Which measure: {ONE_MOTION}." and "most efficient" not in blocks[0].text


def test_a_hazard_in_the_stores_measure_only_is_not_called_a_comparison() -> None:
    import pandas as pd

    from stochpound.report.sections._risk import _measure_choice_blocks
    from stochpound.risk import HazardCurve, StoreRisk

    choice = pd.DataFrame([{"where": "all runs", "PSA(1 s)": 0.5, "most efficient": "PSA(1 s)", "best candidate": "PGV", "best β": 0.4}])
    choice.attrs.update(hazard_measures=["PSA(1 s)"], store_measure="PSA(1 s)", unjudged="")
    risk = StoreRisk(xr.Dataset(), xr.Dataset(), xr.Dataset(), None, "", HazardCurve.power_law(1e-4, 2.0), 20, "stripes", stripes=7)
    text = _measure_choice_blocks("s", risk, choice)[0].text
    assert "no other measure is compared with it" in text and "the most efficient in every" not in text


@pytest.mark.parametrize(("own_beta", "verdict"), [(0.52, "within twice"), (0.70, "beyond twice"), (0.50, "the most efficient in every")])
def test_the_verdict_on_the_stores_own_measure_follows_the_numbers(own_beta: float, verdict: str) -> None:
    import pandas as pd

    from stochpound.report.sections._risk import _measure_choice_blocks
    from stochpound.risk import HazardCurve, StoreRisk

    choice = pd.DataFrame([{"where": "all runs", "PGA": 0.50, "PSA(1 s)": own_beta, "most efficient": "PGA" if own_beta > 0.50 else "PSA(1 s)",
                            "best candidate": "PGV", "best β": 0.4}])
    choice.attrs.update(hazard_measures=["PGA", "PSA(1 s)"], store_measure="PSA(1 s)", unjudged="")
    risk = StoreRisk(xr.Dataset(), xr.Dataset(), xr.Dataset(), None, "", HazardCurve.power_law(1e-4, 2.0), 20, "stripes",
                     setting={"measure": "psa", "period": 1.0, "units": "g"}, stripes=7)
    text = _measure_choice_blocks("s", risk, choice)[0].text
    assert text.count("The store is conditioned on PSA(1 s)") == 1 and verdict in text
    if verdict != "the most efficient in every":
        assert f"by up to {own_beta - 0.50:.3f}" in text and f"≈ {own_beta / np.sqrt(2 * 138):.3f}" in text
