"""The roofline's kernels-alone section (femtools.docs.kernels_alone) and its place in
`fem-tools docs lessons`: data without the section render a line that says so, data with it a
row per chapter and thread count from its numbers, and the section is written only where the
page has its markers."""
import json
import pathlib

from femtools.docs import kernels_alone, lessons

ROOT = pathlib.Path(__file__).resolve().parents[2]


def run(chapter, threads, in_core, between):
    kernel = {"kernel": "product q = A p", "part": "pcg", "calls": 19, "seconds": 4e-5, "bound_s": 1e-5}
    return {"chapter": chapter, "mesh": "plate_poster.msh", "threads": threads, "solve_s": 7e-3,
            "solve_bound_s": 1.5e-3, "parts_bound_s": 1e-3, "alone_s": 1e-3 + in_core,
            "in_core_s": in_core, "between_s": between, "waiting_s": 0.0, "kernels": [kernel]}


def test_data_without_the_section_say_not_recorded():
    committed = json.loads((ROOT / "docs" / "data" / "lessons" / "roofline.json").read_text())
    data = dict(committed["data"])
    data.pop("kernels_alone", None)
    assert kernels_alone.section(data) == kernels_alone.NOT_RECORDED
    assert kernels_alone.section(None) == kernels_alone.NOT_RECORDED


def test_a_row_per_run_from_its_numbers():
    text = kernels_alone.section({"kernels_alone": [run("12_half_the_bytes", 1, 3e-3, 1e-3),
                                                    run("09_threads", 2, 1e-3, 4e-3)]})
    rows = [line for line in text.splitlines() if line.startswith("| `")]
    assert len(rows) == 2
    assert rows[0].startswith("| `12_half_the_bytes@1` | 7.000 | 1.500 | 4.000 (1.000) | 3.000 | 1.000 |")
    assert rows[0].endswith("| product q = A p 25% |")
    fast = run("09_threads", 1, 0.0, 1e-3)
    fast["kernels"][0]["seconds"] = 5e-6
    assert "product q = A p 200% (faster than its bound)" in kernels_alone.section({"kernels_alone": [fast]})
    assert "`12_half_the_bytes@1` in the core; `09_threads@2` between the kernels." in text


def test_written_only_between_its_markers():
    data = {"lesson": "roofline", "data": {"kernels_alone": [run("13_fewer_waits", 1, 1e-3, 2e-3)]}}
    page = f"intro\n<!-- {kernels_alone.MARKER}:begin -->\nold\n<!-- {kernels_alone.MARKER}:end -->\n"
    written = lessons.with_data_sections(page, data)
    assert "old" not in written and "`13_fewer_waits@1`" in written
    assert lessons.with_data_sections("no markers\n", data) == "no markers\n"
    assert lessons.with_data_sections(None, data) is None


def test_a_chapter_readme_takes_the_rows_of_the_chapters_its_marker_names(tmp_path):
    readme = tmp_path / "chapters" / "14_every_lane" / "README.md"
    readme.parent.mkdir(parents=True)
    name = f"{kernels_alone.MARKER}:12,14"
    readme.write_text(f"# Chapter 14: x\n<!-- {name}:begin -->\nold\n<!-- {name}:end -->\n")
    other = tmp_path / "chapters" / "13_fewer_waits" / "README.md"
    other.parent.mkdir(parents=True)
    other.write_text("# Chapter 13: y\nno marker\n")
    data = {"kernels_alone": [run("12_half_the_bytes", 1, 1e-3, 2e-3), run("13_fewer_waits", 1, 1e-3, 2e-3),
                              run("14_every_lane", 2, 1e-3, 2e-3)]}
    changed = lessons.chapter_kernels_alone(tmp_path, data)
    assert list(changed) == [readme]
    text = changed[readme]
    assert "old" not in text and "`12_half_the_bytes@1`" in text and "`14_every_lane@2`" in text
    assert "`13_fewer_waits@1`" not in text
    readme.write_text(text)
    assert lessons.chapter_kernels_alone(tmp_path, data) == {}
