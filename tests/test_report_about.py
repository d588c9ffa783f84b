"""'About this report' says only what the report holds, and the summary's pointers name the sections that hold the details."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import xarray as xr

from stochpound.report.assemble import _about
from stochpound.report.render._document import FigureItem, Paragraph, Section
from stochpound.report.sections._summary import _where


def _sections(*keys: str, figures: tuple[str, ...] = ()) -> list[Section]:
    sections = [Section(key, [Paragraph("text")], key=key) for key in keys]
    sections[0].blocks += [FigureItem(key, "caption", plt.figure()) for key in figures]
    return sections


def test_a_risk_report_is_not_said_to_hold_ecdfs_or_convergence_figures():
    stores = {"pair": xr.Dataset(attrs={"experiment_description": "a pair"})}
    text = _about(stores, _sections("risk-pair", "intensity-pair", "methods"))
    assert "Risk section" in text and "Intensity section" in text
    assert "ECDF" not in text and "convergence" not in text and "synthetic ensemble" not in text
    with_figures = _about(stores, _sections("experiment-pair", "methods", figures=("figure-pair-kt-ecdf-peak", "figure-pair-kt-convergence-pounding")))
    assert "An ECDF gives" in with_figures and "A convergence figure" in with_figures
    plt.close("all")


def test_the_summary_points_a_risk_experiment_to_its_risk_and_intensity_sections():
    sections = _sections("about", "risk-pair", "risk-other", "intensity-pair", "methods")
    assert _where("pair", sections) == ("Details: section 3 (risk-pair), section 5 (intensity-pair), section 6 (methods).")


def test_a_damage_section_is_named_only_where_the_report_has_one():
    stores = {"pair": xr.Dataset(attrs={"experiment_description": "a pair"})}
    assert "A Damage section" not in _about(stores, _sections("risk-pair", "methods"))
    assert "A Damage section per experiment of yielding buildings" in _about(stores, _sections("risk-pair", "damage-pair", "methods"))


def test_the_summary_points_a_yielding_experiment_to_its_damage_section():
    sections = _sections("about", "risk-pair", "damage-pair", "intensity-pair", "methods")
    assert _where("pair", sections) == ("Details: section 3 (risk-pair), section 4 (damage-pair), section 5 (intensity-pair), section 6 (methods).")
