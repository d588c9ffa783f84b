"""The start-up benchmark's section (benchmarks.startup): its rows, medians and same-session ratios, from given times."""

from benchmarks import startup
from benchmarks.sections import keep_sections


def _rows(empty: list[float], warm: list[float]) -> list[dict]:
    rows = []
    for round_, (cold, hot) in enumerate(zip(empty, warm), start=1):
        rows.append({"round": round_, "cache": "empty", "first_case": cold, "setup": cold - 2.0, "running": 4.0, "load": 1.5, "cpu": cold / 2})
        rows.append({"round": round_, "cache": "warm", "first_case": hot, "setup": hot - 1.0, "running": 4.0, "load": 1.5, "cpu": hot})
    return rows


def test_the_section_gives_every_run_the_medians_and_the_ratio_to_the_earlier_revision():
    results = {"rounds": {"this tree": _rows([12.0, 30.0, 11.0], [2.5, 9.0, 2.0]), "abc1234": _rows([48.0, 40.0, 44.0], [6.0, 5.0, 7.0])},
               "elapsed": 300.0, "load_end": "1.20"}
    info = {"commit": "f00ba47", "date": "2026-12-01 23:00 UTC", "load average (1 min) at start": "0.90"}
    text = startup.section(results, info)
    assert text.startswith(startup.SECTION.start) and text.rstrip().endswith(startup.SECTION.end)
    assert "| this tree | 2 | empty | 30.0 | 28.0 | 15.0 | 4.0 | 1.50 |" in text
    assert "| this tree | 12.0 | 2.5 | ≤ 15 s / ≤ 3 s |" in text  # medians: 12 of (12, 30, 11), 2.5 of (2.5, 9, 2)
    assert "| abc1234 | 44.0 | 6.0 |" in text
    assert "This tree against abc1234, measured in the same session: 0.27× with an empty cache and 0.42× with a warm cache" in text
    assert "CPU time to the first case (all the run's processes, less sensitive to other work on the machine): 0.27× with an empty cache and 0.42× with a warm cache." in text
    assert keep_sections(f"# Old\n\n{text}", "# New\n", (startup.SECTION,)) == f"# New\n\n{text}"


def test_without_an_earlier_revision_no_ratio_is_given():
    results = {"rounds": {"this tree": _rows([12.0], [2.5])}, "elapsed": 60.0, "load_end": "0.50"}
    text = startup.section(results, {"commit": "f00ba47", "date": "today", "load average (1 min) at start": "0.40"})
    assert "| this tree | 12.0 | 2.5 |" in text and "measured in the same session" not in text
