"""benchmarks.stripe_tails: the model's own stripes, the tail a lognormal stripe expects, and the shape of ln D in a stripe."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import special, stats

from benchmarks import measure_seeds, stripe_tails


def test_a_model_stripe_is_the_runs_nearest_its_level_in_ln() -> None:
    measure = np.array([0.1, 0.2, 0.4, 0.8, 1.6])
    closure = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    stripes = stripe_tails.nearest_stripes(measure, closure, np.array([0.19, 1.0]), 2)
    # 0.19: 0.2 (ln distance 0.05), then 0.1 (0.64) before 0.4 (0.74); 1.0: 0.8 (0.22), then 1.6 (0.47)
    assert stripes.tolist() == [[2.0, 1.0], [4.0, 5.0]]


def test_the_lognormal_tail_counts_the_runs_beyond_and_what_each_stripe_s_lognormal_expects() -> None:
    rng = np.random.default_rng(3)
    stripes = np.exp(rng.normal([[-1.0], [0.0]], [[0.5], [0.8]], size=(2, 30)))
    stripes[1, :5] = np.nan  # five motions that did not run at the second stripe
    gap = 1.5
    shares = [special.ndtr((np.log(row[np.isfinite(row)]).mean() - np.log(gap)) / np.log(row[np.isfinite(row)]).std(ddof=1)) for row in stripes]
    assert shares[0] < 0.1 < shares[1]  # the gap in the first stripe's tail, not the second's
    observed, expected = stripe_tails.lognormal_tail(stripes, gap)
    assert observed == int(np.count_nonzero(stripes[0] >= gap))
    assert expected == pytest.approx(30 * shares[0], rel=1e-12)
    observed, expected = stripe_tails.lognormal_tail(stripes, gap, tail=1.0)  # every stripe
    assert observed == int(np.count_nonzero(stripes[np.isfinite(stripes)] >= gap))
    assert expected == pytest.approx(30 * shares[0] + 25 * shares[1], rel=1e-12)


def test_a_right_skewed_stripe_has_more_runs_beyond_its_tail_than_its_lognormal_expects() -> None:
    """ln D = Z + Z² (right-skewed): far in the tail the runs beyond outnumber the fitted lognormal's expectation; a lognormal
    stripe's runs do not."""
    z = np.random.default_rng(0).standard_normal((4, 5000))
    skewed, normal = np.exp(z + z ** 2), np.exp(z)
    gap = float(np.quantile(skewed, 0.995))
    observed, expected = stripe_tails.lognormal_tail(skewed, gap, tail=1.0)
    assert observed > 3.0 * expected
    assert stripe_tails.skewness(skewed) > 1.0
    gap = float(np.quantile(normal, 0.995))
    observed, expected = stripe_tails.lognormal_tail(normal, gap, tail=1.0)
    assert observed == pytest.approx(expected, rel=0.25)
    assert abs(stripe_tails.skewness(normal)) < 0.1


def test_skewness_is_the_median_over_stripes_of_ln_d_s_sample_skewness() -> None:
    rng = np.random.default_rng(1)
    stripes = np.exp(rng.gamma([[1.0], [2.0], [9.0]], size=(3, 50)))
    assert stripe_tails.skewness(stripes) == pytest.approx(np.median([stats.skew(np.log(row)) for row in stripes]), rel=1e-12)


def test_the_measures_of_a_motion_are_its_pga_and_its_pseudo_spectral_accelerations() -> None:
    from stochpound.motions import DEFAULT_G, response_spectrum

    t = np.arange(0, 10, 0.01)
    acceleration = np.vstack([np.sin(2 * np.pi * t) * np.exp(-0.2 * t), 0.5 * np.sin(2 * np.pi * 0.4 * t)]) * DEFAULT_G
    values = measure_seeds.measure_values(acceleration, 0.01, ["PGA", "PSA(2 s)", "Sa_avg(0.5-4 s)"])
    assert values["PGA"] == pytest.approx(np.abs(acceleration).max(axis=1) / DEFAULT_G, rel=1e-12)
    for row, a in enumerate(acceleration):
        psa = response_spectrum(a, 0.01, np.array([0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0]))["psa"].values / DEFAULT_G
        assert values["PSA(2 s)"][row] == pytest.approx(psa[3], rel=1e-9)
        assert values["Sa_avg(0.5-4 s)"][row] == pytest.approx(np.exp(np.log(psa).mean()), rel=1e-9)


def test_a_missing_store_or_too_few_nearest_runs_is_refused_in_one_line(tmp_path, capsys) -> None:
    with pytest.raises(SystemExit):
        stripe_tails.main([str(tmp_path), "--configurations", "isolated", "--seeds", "1"])
    assert "isolated, seed 1: no store" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        stripe_tails.main([str(tmp_path), "--nearest", "1"])
    assert "--nearest: must be 2 to --motions" in capsys.readouterr().err


def test_a_store_missing_at_any_seed_is_refused_before_the_model_s_world_is_made(tmp_path, capsys) -> None:
    from benchmarks.measure_seeds import work_folder
    from benchmarks.site_consistency import experiment_file

    for measure in ("PGA", "PSA(2 s)"):  # seed 1's stores there (empty files: the check reads none), seed 2's not
        path = experiment_file(work_folder(tmp_path, "isolated", 1), measure).with_suffix(".nc")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.touch()
    with pytest.raises(SystemExit):
        stripe_tails.main([str(tmp_path), "--configurations", "isolated", "--measures", "PGA", "PSA(2 s)", "--seeds", "1", "2"])
    assert "isolated, seed 2: no store pga.nc" in capsys.readouterr().err
