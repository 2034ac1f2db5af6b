"""The machine, compiler and commit a timed table's caption names (femtools.docs.provenance):
a run's own record; a lesson's own build and commit; a lesson recorded before it kept them takes
the book sitting's, only when the book lists it with its hash; otherwise the caption says what
is not recorded. And `fem-tools docs lessons` writes them under the table."""
import hashlib
import json
import pathlib

from femtools.docs import lessons, provenance

MACHINE = {"cpu": "AMD EPYC", "model_name": "AMD EPYC", "cores": 2}
BUILD = {"compiler": "GNU 12.2.0", "flags": "-O3"}


def test_a_run_names_its_machine_compiler_and_commit():
    run = {"machine": MACHINE, "build": BUILD, "commit": "fa0a74e"}
    assert provenance.of_run(run) == "AMD EPYC (2 cores), GNU 12.2.0, commit fa0a74e"
    assert provenance.of_run({}) == "machine not recorded, compiler not recorded, commit not recorded"


def write_book(root, lesson_path, listed=True):
    data = root / "docs" / "data"
    (data / "bench.json").write_text(json.dumps({"machine": MACHINE, "build": BUILD, "commit": "abc1234"}))
    digest = lambda p: hashlib.sha256(p.read_bytes()).hexdigest()  # noqa: E731
    files = {"docs/data/bench.json": digest(data / "bench.json")}
    if listed:
        files[lesson_path.relative_to(root).as_posix()] = digest(lesson_path)
    (data / "book.json").write_text(json.dumps({"commit": "abc1234def", "data": files}))


def lesson_file(root, record):
    path = root / "docs" / "data" / "lessons" / "spmv.json"
    path.parent.mkdir(parents=True)
    path.write_text(json.dumps(record))
    return path


def test_a_lesson_takes_its_own_record_or_the_sittings(tmp_path):
    own = {"machine": MACHINE, "build": BUILD, "commit": "1234567"}
    path = lesson_file(tmp_path, own)
    write_book(tmp_path, path)
    assert provenance.of_lesson(tmp_path, path, own).endswith("GNU 12.2.0, commit 1234567")
    old = {"machine": MACHINE}
    path.write_text(json.dumps(old))
    write_book(tmp_path, path)
    assert provenance.of_lesson(tmp_path, path, old) == "AMD EPYC (2 cores), GNU 12.2.0, commit abc1234"
    write_book(tmp_path, path, listed=False)
    assert provenance.of_lesson(tmp_path, path, old).endswith("compiler not recorded, commit not recorded")


def test_the_caption_adds_the_commit_or_all_three(tmp_path):
    named = {"machine": MACHINE, "build": BUILD, "commit": "1234567",
             "table": "| a |\n| --- |\n| 1 |\n\nAMD EPYC, GNU 12.2.0, `-O3`.\n"}
    table, _ = lessons.with_provenance(tmp_path, tmp_path / "x.json", named)
    assert table.endswith("`-O3`. Recorded at commit 1234567.\n")
    bare = dict(named, table="| a |\n| --- |\n| 1 |\n\nMedians of 10 steps\n")
    table, _ = lessons.with_provenance(tmp_path, tmp_path / "x.json", bare)
    assert table.endswith("Medians of 10 steps. Recorded on AMD EPYC (2 cores), GNU 12.2.0, commit 1234567.\n")
    counts = {"table": "| a |\n| --- |\n| 1 |\n"}
    assert lessons.with_provenance(tmp_path, tmp_path / "x.json", counts) == (counts["table"], None)


def test_every_table_of_a_block_names_where_it_was_recorded_under_itself(tmp_path):
    where = "AMD EPYC (2 cores), GNU 12.2.0, commit 1234567"
    block = {"machine": MACHINE, "build": BUILD, "commit": "1234567",
             "table": "| a |\n| --- |\n| 1 |\n\n| b |\n| --- |\n| 2 |\n\nMedians of 50.\n\n"
                      "| c |\n| --- |\n| 3 |\n\nAMD EPYC, GNU 12.2.0, commit 1234567.\n"}
    table, _ = lessons.with_provenance(tmp_path, tmp_path / "x.json", block)
    assert table == ("| a |\n| --- |\n| 1 |\n\nRecorded on " + where + ".\n\n| b |\n| --- |\n| 2 |\n\n"
                     "Medians of 50. Recorded on " + where + ".\n\n| c |\n| --- |\n| 3 |\n\n"
                     "AMD EPYC, GNU 12.2.0, commit 1234567.\n")
    last = dict(block, table="| a |\n| --- |\n| 1 |\n")
    table, _ = lessons.with_provenance(tmp_path, tmp_path / "x.json", last)
    assert table.endswith("| 1 |\n\nRecorded on " + where + ".\n")


def test_chapter_13s_measured_section_from_the_committed_data():
    from femtools.docs import fewer_waits
    root = pathlib.Path(__file__).resolve().parents[2]
    bench = json.loads((root / "docs" / "data" / "bench.json").read_text())
    roofline = json.loads((root / "docs" / "data" / "lessons" / "roofline.json").read_text())
    text = fewer_waits.section(bench, roofline)
    assert text.count("over chapter 12") == 2 and "priced by the roofline at 2 threads" in text
    assert "the control at 1 thread" in text and "between the kernels" in text
    assert provenance.of_run(bench) in text
    assert "no chapters 12 and 13" in fewer_waits.section({"chapters": [], "mesh": {"file": "x"}}, None)


def test_dirty_only_where_a_measured_source_differed():
    assert provenance.short_commit("fa0a74e-dirty", []) == "fa0a74e"
    assert provenance.short_commit("fa0a74e-dirty", ["chapters/13_x/stepper.hpp"]) == "fa0a74e-dirty"
    assert provenance.short_commit("fa0a74e-dirty") == "fa0a74e-dirty"
    assert provenance.short_commit("fa0a74e9015d") == "fa0a74e"
