"""The sections of docs/benchmarks.md written by their own commands survive the main suite's rewrite."""

from benchmarks import compare, experiment_scale
from benchmarks.sections import Section, keep_sections


def test_a_section_is_replaced_in_place_and_appended_when_absent(tmp_path):
    section = Section("<!-- s: start -->", "<!-- s: end -->")
    path = tmp_path / "benchmarks.md"
    path.write_text("# Title\n\nbody\n")
    section.write(path, "<!-- s: start -->\nfirst\n<!-- s: end -->\n")
    assert path.read_text() == "# Title\n\nbody\n\n<!-- s: start -->\nfirst\n<!-- s: end -->\n"
    path.write_text(path.read_text() + "\ntail\n")
    section.write(path, "<!-- s: start -->\nsecond\n<!-- s: end -->")
    assert path.read_text() == "# Title\n\nbody\n\n<!-- s: start -->\nsecond\n<!-- s: end -->\n\ntail\n"


def test_the_main_suite_keeps_the_scaling_and_comparison_sections():
    scaling, comparison = experiment_scale.SECTION, compare.SECTION
    old = f"# Old\n\nold body\n\n{comparison.start}\nA/B\n{comparison.end}\n\n{scaling.start}\nscale\n{scaling.end}\n"
    new = keep_sections(old, "# New\n\nnew body\n", (scaling, comparison))
    assert new == f"# New\n\nnew body\n\n{scaling.start}\nscale\n{scaling.end}\n\n{comparison.start}\nA/B\n{comparison.end}\n"
    assert keep_sections("# Old\n", "# New\n", (scaling, comparison)) == "# New\n"
