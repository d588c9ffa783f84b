"""Mean annual frequency, the pounding risk curve, the risk-targeted separation, demand hazard and the code rules in risk terms."""

import numpy as np
import pytest
import xarray as xr
from scipy import integrate, stats

from stochpound.analysis import HazardCurve, fit_fragility, mean_annual_frequency, rate_from_probability, separation_rules
from stochpound.risk import (
    Fragility,
    code_rules_risk,
    contact_free_closure,
    demand_hazard_curve,
    limit_state_events,
    pounding_fragility,
    risk_curve,
    risk_targeted_separation,
    stripe_fragility,
)


def closed_form(k0, k, theta, beta):
    return k0 * theta**-k * np.exp(k**2 * beta**2 / 2.0)


@pytest.mark.parametrize(("k0", "k", "theta", "beta"), [(1e-4, 2.5, 0.5, 0.4), (2e-4, 1.5, 0.1, 0.8), (5e-5, 3.5, 2.0, 0.2), (1e-3, 2.0, 1.0, 1.2)])
def test_maf_of_a_lognormal_fragility_and_a_power_law_equals_the_closed_form(k0, k, theta, beta):
    assert mean_annual_frequency(Fragility(theta, beta), HazardCurve.power_law(k0, k)) == pytest.approx(closed_form(k0, k, theta, beta), rel=1e-3)


def test_maf_over_a_tabulated_power_law_equals_the_closed_form():
    im = np.geomspace(1e-3, 20.0, 25)
    table = HazardCurve(im, 1e-4 * im**-2.5)
    assert mean_annual_frequency(Fragility(0.5, 0.4), table) == pytest.approx(closed_form(1e-4, 2.5, 0.5, 0.4), rel=1e-2)


def test_maf_over_a_curved_table_equals_an_independent_quadrature_of_f_dlambda():
    im = np.geomspace(0.01, 3.0, 25)
    hz = HazardCurve(im, 1e-2 * np.exp(-3.0 * im) * im**-0.8)
    theta, beta = 0.6, 0.5

    def f_dlambda(x):  # F(x) |dλ/dx| on the log-log interpolant, differentiated numerically
        h = 1e-6 * x
        return stats.norm.cdf(np.log(x / theta) / beta) * (hz(x - h) - hz(x + h)) / (2.0 * h)

    inside = integrate.quad(f_dlambda, im[0] * (1 + 1e-9), im[-1] * (1 - 1e-9), points=im[1:-1], limit=400)[0]
    expected = inside + stats.norm.cdf(np.log(im[-1] / theta) / beta) * hz(im[-1])  # the rate above the table, at its last intensity
    assert mean_annual_frequency(Fragility(theta, beta), hz) == pytest.approx(expected, rel=1e-4)


def test_degenerate_fragilities_give_the_rate_at_their_step():
    hz = HazardCurve([0.1, 0.5, 1.0], [1e-2, 1e-3, 1e-4])
    assert mean_annual_frequency(fit_fragility([0.2, 0.4], [0, 0], [5, 5]), hz) == 0.0
    assert mean_annual_frequency(fit_fragility([0.2, 0.4], [5, 5], [5, 5]), hz) == pytest.approx(1e-2)
    assert mean_annual_frequency(Fragility(0.5, 0.0), hz) == pytest.approx(1e-3)
    assert np.isnan(mean_annual_frequency(Fragility(np.nan, np.nan), hz))


def test_maf_broadcasts_over_data_arrays():
    theta = xr.DataArray([0.3, 0.6], dims="gap")
    rate = mean_annual_frequency(Fragility(theta, xr.DataArray(0.4)), HazardCurve.power_law(1e-4, 2.0))
    assert rate.dims == ("gap",) and rate.attrs["units"] == "1/yr"
    assert rate.values == pytest.approx(closed_form(1e-4, 2.0, theta.values, 0.4), rel=1e-6)


def gap_fragility(gaps, slope=4.0, beta=0.4):
    """θ(g) = slope · g: the fragility of a linear pair (IDA from one run)."""
    g = xr.DataArray(gaps, dims="gap", coords={"gap": gaps})
    return xr.Dataset({"theta": slope * g, "beta": xr.full_like(g, beta)})


def test_the_risk_targeted_separation_inverts_the_risk_curve():
    k0, k, slope, beta = 2e-4, 2.4, 4.0, 0.4
    hz = HazardCurve.power_law(k0, k)
    curve = risk_curve(gap_fragility(np.linspace(0.01, 0.5, 50), slope, beta), hz)
    assert curve.maf.values == pytest.approx(closed_form(k0, k, slope * curve.gap.values, beta), rel=1e-6)
    assert curve.probability.values == pytest.approx(1 - np.exp(-50 * curve.maf.values))
    result = risk_targeted_separation(curve)
    assert result.target.values.tolist() == [0.10, 0.02]
    for p in (0.10, 0.02):
        separation = float(result.separation.sel(target=p))
        assert mean_annual_frequency(Fragility(slope * separation, beta), hz) == pytest.approx(rate_from_probability(p), rel=1e-9)
        exact = (k0 * np.exp(k**2 * beta**2 / 2) / rate_from_probability(p)) ** (1 / k) / slope
        assert separation == pytest.approx(exact, rel=1e-9)


def test_the_separation_is_inf_beyond_the_grid_and_its_first_gap_below():
    hz = HazardCurve.power_law(2e-4, 2.4)
    assert float(risk_targeted_separation(risk_curve(gap_fragility(np.linspace(0.001, 0.01, 5)), hz), [0.02]).separation[0]) == np.inf
    assert float(risk_targeted_separation(risk_curve(gap_fragility(np.linspace(5.0, 6.0, 5)), hz), [0.02]).separation[0]) == 5.0
    with pytest.raises(ValueError, match="^gap"):
        risk_targeted_separation(risk_curve(gap_fragility(np.array([0.2, 0.1])), hz))


def stripes_of_a_linear_pair(records=30, seed=0):
    """Contact-free closures D = x · d_r (linear in the intensity x) with lognormal d_r, at 7 stripes."""
    rng = np.random.default_rng(seed)
    levels = np.array([0.1, 0.2, 0.35, 0.5, 0.7, 0.9, 1.2])
    d = np.exp(rng.normal(np.log(0.08), 0.5, records))
    closure = xr.DataArray(levels[:, None] * d[None, :], dims=("intensity", "record"), coords={"intensity": levels})
    return closure, d


def test_the_whole_chain_from_stripes_brackets_g_star_and_recovers_the_ida_answer():
    closure, d = stripes_of_a_linear_pair(records=40)
    hz = HazardCurve.power_law_through((0.4, rate_from_probability(0.10)), (0.8, rate_from_probability(0.02)))
    gaps = np.linspace(0.005, 0.2, 60)
    curve = risk_curve(stripe_fragility(limit_state_events(closure, gaps), bootstrap=200), hz)
    assert np.all(curve.maf_lower <= curve.maf) and np.all(curve.maf <= curve.maf_upper)
    result = risk_targeted_separation(curve)
    assert np.all(result.lower <= result.separation) and np.all(result.separation <= result.upper)
    # the exact fragility of this pair: pounding at gap g iff x d_r >= g, i.e. capacity g / d_r
    slope, beta = 1.0 / np.exp(np.mean(np.log(d))), np.std(np.log(d))
    reference = risk_targeted_separation(risk_curve(gap_fragility(gaps, slope, beta), hz))
    assert result.separation.values == pytest.approx(reference.separation.values, rel=0.15)


def test_demand_hazard_curve_decreases_with_the_level():
    closure, _ = stripes_of_a_linear_pair()
    hz = HazardCurve.power_law(2e-4, 2.4)
    curve = demand_hazard_curve(closure, [0.01, 0.03, 0.1], hz, bootstrap=0)
    assert curve.maf.dims == ("level",) and np.all(np.diff(curve.maf.values) < 0)


def contact_demands_at_stripes(records=12, contacts=2, seed=3):
    rng = np.random.default_rng(seed)
    levels = np.array([0.2, 0.4, 0.6, 0.8, 1.0])
    a, b = np.exp(rng.normal(np.log(0.05), 0.4, records)), np.exp(rng.normal(np.log(0.08), 0.4, records))
    rho = rng.uniform(0.0, 0.5, (records, contacts))
    shape = (levels.size, records, contacts)
    u1 = np.broadcast_to(levels[:, None, None] * a[None, :, None], shape)
    u2 = np.broadcast_to(levels[:, None, None] * b[None, :, None], shape)
    closure = np.sqrt(u1**2 + u2**2 - 2 * rho * u1 * u2) * np.exp(rng.normal(0.0, 0.15, shape))
    dims = ("intensity", "record", "contact")
    demands = xr.Dataset({"peak_displacement_left": (dims, u1), "peak_displacement_right": (dims, u2),
                          "correlation": (dims, np.broadcast_to(rho, shape)), "peak_closure": (dims, closure)},
                         coords={"intensity": levels, "gap": np.inf})
    isolator = xr.DataArray(levels[:, None] * b[None, :] * 1.3, dims=("intensity", "record"), coords={"intensity": levels})
    return demands, isolator


def test_code_rules_in_risk_terms_apply_the_rules_to_the_suite_means_at_the_code_stripe():
    demands, isolator = contact_demands_at_stripes()
    hz = HazardCurve.power_law_through((0.4, rate_from_probability(0.10)), (0.8, rate_from_probability(0.02)))
    result = code_rules_risk(demands, hz, isolator_displacement=isolator, bootstrap=100)
    assert result.rule.values.tolist() == ["abs", "srss", "srss_reduced", "ddc", "dtm"]
    assert result.code_intensity.values == pytest.approx([0.8, 0.4])
    mce = result.sel(design_level=0.02)
    at_stripe = demands.sel(intensity=0.8).mean("record")
    rules = separation_rules(at_stripe.drop_vars("gap"))
    assert mce.gap.sel(rule="srss").values == pytest.approx(rules.sel(rule="srss").values)
    assert mce.gap.sel(rule="dtm").values == pytest.approx(float(isolator.sel(intensity=0.8).mean()))
    # λ_P of the SRSS gap: the stripes' fragility of max_c (D_c − g_c) >= 0, integrated with the hazard
    events = ((demands.peak_closure - rules.sel(rule="srss")).max("contact") >= 0).astype(float)
    expected = mean_annual_frequency(stripe_fragility(events.drop_vars("gap"), bootstrap=0), hz)
    assert float(mce.maf.sel(rule="srss")) == pytest.approx(float(expected))
    assert float(mce.maf.sel(rule="abs")) < float(mce.maf.sel(rule="srss")) < float(mce.maf.sel(rule="srss_reduced"))
    assert np.all(result.maf_lower <= result.maf) and np.all(result.maf <= result.maf_upper)
    assert np.all(result.gap_lower <= result.gap) and np.all(result.gap <= result.gap_upper)
    assert np.all(result.gap_lower < result.gap_upper)  # the rule's gap is recomputed from each resample
    assert result.return_period.values == pytest.approx(1 / result.maf.values)
    table = result[["gap", "maf"]].to_dataframe()
    assert len(table) == 2 * 5 * 2


def test_code_rules_on_a_conditional_spectrum_store_average_only_each_stripe_s_chosen_motions():
    # a CS store: a pool of 12 motions, 8 chosen per stripe, the other 4 NaN (never ran at that stripe)
    demands, isolator = contact_demands_at_stripes()
    rng = np.random.default_rng(11)
    chosen = np.array([np.isin(np.arange(12), rng.choice(12, 8, replace=False)) for _ in range(demands.sizes["intensity"])])
    mask = xr.DataArray(chosen, dims=("intensity", "record"))
    demands, isolator = demands.where(mask), isolator.where(mask)
    hz = HazardCurve.power_law_through((0.4, rate_from_probability(0.10)), (0.8, rate_from_probability(0.02)))
    mce = code_rules_risk(demands, hz, isolator_displacement=isolator, bootstrap=0).sel(design_level=0.02)
    picked = chosen[3]  # the stripe at 0.8
    at_stripe = demands.sel(intensity=0.8).isel(record=np.flatnonzero(picked))
    rules = separation_rules(at_stripe.mean("record").drop_vars("gap"))
    assert mce.gap.sel(rule="srss").values == pytest.approx(rules.sel(rule="srss").values)
    assert mce.gap.sel(rule="dtm").values == pytest.approx(float(isolator.sel(intensity=0.8)[picked].mean()))
    events = ((demands.peak_closure - rules.sel(rule="srss")).max("contact", skipna=False) >= 0).astype(float).where(mask)
    expected = mean_annual_frequency(stripe_fragility(events.drop_vars("gap"), bootstrap=0), hz)
    assert float(mce.maf.sel(rule="srss")) == pytest.approx(float(expected))
    with pytest.raises(ValueError, match="^record: the codes take the mean over at least 7 motions, got 6"):
        code_rules_risk(contact_demands_at_stripes()[0].where(xr.DataArray(np.arange(12) < 6, dims="record")), hz)


def test_code_rules_need_seven_motions_and_the_demands():
    demands, _ = contact_demands_at_stripes(records=5)
    hz = HazardCurve.power_law(2e-4, 2.4)
    with pytest.raises(ValueError, match="^record: the codes take the mean over at least 7"):
        code_rules_risk(demands, hz)
    with pytest.raises(ValueError, match="^demands: missing 'correlation'"):
        code_rules_risk(demands.drop_vars("correlation"), hz)


def synthetic_store(seed=4):
    """A store-shaped Dataset: (gap with inf, mu, record, intensity, contact) peak closures; only gap = inf is contact-free."""
    rng = np.random.default_rng(seed)
    gaps, mu, levels = [0.02, 0.05, np.inf], [0.05, 0.1], [0.2, 0.4, 0.6, 0.8]
    values = rng.lognormal(np.log(0.04), 0.5, (3, 2, 10, 4, 2)) * np.array(levels)[:, None]
    dims = ("gap", "mu", "record", "intensity", "contact")
    return xr.Dataset({"peak_contact_closure": (dims, values)}, coords={"gap": gaps, "mu": mu, "intensity": levels})


def test_the_store_selection_takes_the_contact_free_cases_for_every_gap_and_configuration():
    store = synthetic_store()
    fragility = pounding_fragility(store, [0.01, 0.03, 0.06], bootstrap=20)
    assert set(fragility.theta.dims) == {"gap", "mu"}
    manual = store.peak_contact_closure.sel(gap=np.inf).max("contact")
    expected = stripe_fragility(limit_state_events(manual, [0.01, 0.03, 0.06]), bootstrap=0)
    assert fragility.theta.transpose(*expected.theta.dims).values == pytest.approx(expected.theta.values, nan_ok=True)
    assert contact_free_closure(store).dims == ("mu", "record", "intensity")
    with pytest.raises(ValueError, match="^store: no contact-free cases"):
        contact_free_closure(store.sel(gap=[0.02, 0.05]))


def test_the_risk_chain_and_the_experiment_layer_select_contact_free_cases_by_the_one_rule():
    """With two gap axes only the cases at inf on both are contact-free, for the risk chain as for the store's door (ds.pound)."""
    rng = np.random.default_rng(7)
    dims = ("gap", "gap_top", "record", "intensity", "contact")
    values = rng.lognormal(np.log(0.04), 0.5, (2, 2, 8, 3, 2))
    store = xr.Dataset({"peak_contact_closure": (dims, values)},
                       coords={"gap": [0.02, np.inf], "gap_top": [np.inf, 0.03], "intensity": [0.2, 0.4, 0.6]})
    closure = contact_free_closure(store)
    assert closure.dims == ("record", "intensity")
    np.testing.assert_array_equal(closure.values, values[1, 0].max(-1))
    np.testing.assert_array_equal(closure.values, store.pound.contact_free().peak_contact_closure.max("contact").values)
    with pytest.raises(ValueError, match="^store: no contact-free cases .*gap, gap_top"):
        contact_free_closure(store.sel(gap_top=[0.03]))
