"""The pieces the commands share, each in one place: the generated sections' markers, the
Markdown tables, the phases (read from the run where it lists them), the poster's numbers, the
size rules for Python, and the docs' sections found by their markers (a new chapter gets its
own without an edit)."""
import importlib
import pathlib
import textwrap

import pytest

from femtools.checks import sizes
from femtools.docs import markdown, markers, update
from femtools.results import phases, poster
from femtools.results.schema import validate_bench

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "femtools"


@pytest.mark.parametrize("module", sorted(str(p.relative_to(PACKAGE.parent).with_suffix("")).replace("/", ".")
                                          for p in PACKAGE.rglob("*.py") if p.name != "__main__.py"))
def test_every_module_imports(module):
    importlib.import_module(module)


def test_a_section_is_replaced_between_its_markers_only():
    text = "a\n<!-- t:begin -->\nold\n<!-- t:end -->\nb <!-- u:begin -->x<!-- u:end -->\n"
    new = markers.replace_between(text, "t", "new\n")
    assert new == "a\n<!-- t:begin -->\nnew\n<!-- t:end -->\nb <!-- u:begin -->x<!-- u:end -->\n"
    assert markers.replace_between(text, "missing", "x\n") is None
    assert markers.names_in(text) == ["t", "u"]


def test_update_file_writes_or_lists_the_stale_sections(tmp_path):
    path = tmp_path / "doc.md"
    path.write_text("<!-- t:begin -->\nold\n<!-- t:end -->\n")
    stale = []
    assert markers.update_file(path, {"t": "new\n", "absent": "x\n"}, stale) == ["t"]
    assert stale == [f"{path}: t"] and "old" in path.read_text()
    markers.update_file(path, {"t": "new\n"})
    assert path.read_text() == "<!-- t:begin -->\nnew\n<!-- t:end -->\n"


def test_markdown_table_and_numbers():
    assert markdown.table(["a", "b"], [["x", 1]]) == "| a | b |\n| --- | ---: |\n| x | 1 |\n"
    assert markdown.table(["a"], [], ["---"]) == "| a |\n| --- |\n"
    assert [markdown.ms(x) for x in (1.23456, 12.3456, 123.456)] == ["1.235", "12.35", "123.5"]
    assert markdown.ratio(3, 2) == "x1.50" and markdown.ratio(1, 0) == "-"


def test_the_phases_are_the_runs_where_it_lists_them():
    assert phases.all_phases() == phases.ALL_PHASES and phases.ALL_PHASES[-1] == "step"
    listed = {"phases": ["forces", "contact", "solve", "step"]}
    assert phases.all_phases(listed) == listed["phases"]
    assert phases.parts(listed) == ["forces", "contact", "solve"]
    assert phases.compared(listed) == ["contact", "solve", "step"]
    assert phases.label("contact") == "contact" and phases.marker("contact") == "x"


def test_the_schema_asks_every_listed_phase_of_every_row():
    times = {p: 1.0 for p in phases.ALL_PHASES}
    row = {"chapter": "01_naive", "allocations_per_step": 0, "cg_iterations": 1, "relative_residual": 0,
           **{t: dict(times) for t in ("median_ms", "min_ms", "q1_ms", "q3_ms", "max_ms")}}
    data = {"phases": phases.ALL_PHASES[:-1] + ["contact", "step"], "chapters": [row]}
    assert any("median_ms: missing 'contact'" in p for p in validate_bench(data))
    assert any("bench.phases" in p for p in validate_bench({"phases": ["forces"], "chapters": [row]}))


def test_the_posters_numbers_are_kept_once():
    assert poster.number("pcg_ch06") == poster.SOLVE_RATIOS["pcg_ch06"] == 4.226
    assert [k for k, _, _ in poster.NUMBERS] == list(poster.SPEEDUPS) + list(poster.SOLVE_RATIOS)
    assert poster.comparable({"mesh": {"file": poster.MESH}, "scene": poster.SCENE})


def test_the_size_rules_read_python(tmp_path):
    def function(lines):
        return "def f():\n" + "    x = 1\n" * (lines - 2) + "    return x\n"
    (tmp_path / "ok.py").write_text(function(60))
    (tmp_path / "long.py").write_text("class A:\n" + textwrap.indent(function(61), "    "))
    (tmp_path / "big.py").write_text("x = 1\n" * 401)
    assert sizes.check_python(tmp_path / "ok.py", tmp_path) == []
    assert sizes.check_python(tmp_path / "long.py", tmp_path) == ["long.py:2: f is 61 lines long (at most 60)"]
    assert sizes.check_python(tmp_path / "big.py", tmp_path) == ["big.py: 401 lines (at most 400)"]


def test_a_new_chapter_gets_its_scaling_sections_by_their_markers(tmp_path):
    for name in ("12_half_the_bytes", "13_next"):
        (tmp_path / "chapters" / name).mkdir(parents=True)
        (tmp_path / "chapters" / name / "stepper.hpp").write_text("")
    runs = [{"chapter": f"{c}@{t}", "mesh": m, "nodes": n, "step_ms": 2.0 * n, "solve_ms": 1.0 * n,
             "cg_iterations": 9} for c in ("12_half_the_bytes", "13_next") for t in (1, 2)
            for m, n in (("beam_500", 500), ("beam_1k", 1000))]
    scaling = {"runs": runs, "scene": "cantilever", "commit": "abc1234"}
    sections = update.chapter_sections(tmp_path, scaling)[tmp_path / "chapters" / "13_next" / "README.md"]
    assert set(sections) == set(update.CHAPTER_SCALING)
    assert "step minus solve, ms: 12 / 13" in sections["scaling-pair"]
    assert "`13_next@1`" in sections["scaling-per-node"] and "`12_half_the_bytes@2`" in sections["scaling-per-node"]
