"""The bundled Fox Plaza curves are the USGS source file, every row of it, verbatim.

The source (``data/hazard/SOURCES.md``) is one CSV: a row ``sa,<levels>`` and one row per measure
(``pga``, ``0.03s``, ..., ``5.0s``) of annual rates of exceedance. Its text is rebuilt here from the 17
bundled files (their value strings as written, in the site's order: PGA, then PSA by period) and its
sha256 compared with the one SOURCES.md states: a changed, rounded, missing or extra value changes it.
"""

from __future__ import annotations

import hashlib
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from stochpound.analysis import HazardCurve, bundled_curves, bundled_measure, bundled_site_curves
from stochpound.experiment._spec import parse_experiment
from stochpound.hazard._curve import bundled_path
from stochpound.hazard._files import StatedMeasure, read_hazard_file
from stochpound.hazard._setting import hazard_curve
from stochpound.store import Hazard
from stochpound.motions import Measure
from tests.helpers import ISOLATED, REPOSITORY, risk_text

SITE = "fox_plaza_los_angeles"
SOURCE_SHA256 = "557c3e086bec6b06e8546a9144432c3f9486388f736792dda50030eb5e5b6b65"
"""sha256 of ``test/lib/foxplaza.csv`` of usgs/earthquake-rtgm-calculator at commit c359753782719e989cd6a781241a717654b88f0f."""
SOURCE_PERIODS = (0.03, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)
"""The periods (s) of the source's PSA rows, after its ``pga`` row."""


def _rows(name: str) -> tuple[str, list[str], list[str]]:
    """A bundled file's source row label (its ``row '...'`` comment) and its two columns as written."""
    lines = bundled_path(name).read_text().splitlines()
    label = re.search(r"row '([^']+)'", "\n".join(lines)).group(1)
    table = [line.split(",") for line in lines[lines.index("im,rate") + 1:]]
    return label, [level for level, _ in table], [rate for _, rate in table]


def test_the_site_s_files_are_the_source_file_verbatim() -> None:
    names = bundled_site_curves(f"{SITE}_pga")
    assert [bundled_measure(name).period for name in names] == [None, *SOURCE_PERIODS]
    rows = [_rows(name) for name in names]
    assert all(levels == rows[0][1] for _, levels, _ in rows), "every file has the source's levels"
    assert [label for label, _, _ in rows] == ["pga", *(f"{name.removeprefix(f'{SITE}_sa').replace('p', '.')[:-1]}s" for name in names[1:])]
    text = "".join(",".join([label, *values]) + "\n" for label, values in [("sa", rows[0][1]), *((label, rates) for label, _, rates in rows)])
    assert hashlib.sha256(text.encode()).hexdigest() == SOURCE_SHA256
    assert SOURCE_SHA256 in (REPOSITORY / "data" / "hazard" / "SOURCES.md").read_text()


@pytest.mark.parametrize("name", [name for name in bundled_curves() if name.startswith(SITE)])
def test_each_file_is_read_with_the_measure_its_name_says(name: str) -> None:
    measure = bundled_measure(name)
    assert read_hazard_file(bundled_path(name)).stated == StatedMeasure.of(measure, "g"), "the file's '# Measure:' line agrees with its name"
    _, levels, rates = _rows(name)
    curve = HazardCurve.bundled(name)
    np.testing.assert_array_equal(curve.im, [float(level) for level in levels])
    np.testing.assert_array_equal(curve.rate, [float(rate) for rate in rates])
    assert curve.units == "g" and np.all(np.diff(curve.rate) < 0.0)


@pytest.mark.parametrize("period", [0.2, 0.3, 0.4])
def test_a_short_building_s_stripes_take_the_site_s_curve_at_their_own_period(tmp_path: Path, period: float) -> None:
    name = f"{SITE}_sa{str(period).replace('.', 'p')}s"
    assert bundled_measure(name) == Measure("psa", period, damping=0.05)
    intensity = f'measure = "psa"\nperiod = {period}\nlevels = [0.3, 0.8, 1.5]'
    text = risk_text(ISOLATED, "gap = [inf]", intensity, f'bundled = "{name}"')
    curve = hazard_curve(Hazard.from_entry(parse_experiment(tomllib.loads(text), base_dir=tmp_path)["hazard"]))
    np.testing.assert_allclose(curve(curve.im), HazardCurve.bundled(name).rate, rtol=1e-12)
