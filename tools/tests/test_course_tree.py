"""The course as a tree (femtools.course.tree.parent_of) and the chapter diffs it gives
(femtools.docs.diffs): each chapter against the one it builds on, a new file as added, the old
text's words kept."""
import pytest

from femtools.course.tree import parent_of
from femtools.docs import diffs


def chapter(root, name, stepper, files=None):
    folder = root / "chapters" / name
    folder.mkdir(parents=True)
    (folder / "stepper.hpp").write_text(stepper)
    for file, text in (files or {}).items():
        (folder / file).write_text(text)
    return folder


def recipe(ns, builds_on=None, includes=()):
    lines = [f'#include "chapters/{i}"' for i in includes]
    lines += [f"namespace fem::{ns} {{", "struct Recipe {"]
    if builds_on:
        lines.append(f"  using BuildsOn = {builds_on};  // the chapter this recipe changes")
    lines += ["};", "using Step = ch08::StepOf<Recipe>;", "}"]
    return "\n".join(lines) + "\n"


@pytest.fixture
def course(tmp_path):
    """Chapters 07 and 08 copies in a line; 12, 13 and 14 recipes, 13 and 14 both on 12."""
    chapter(tmp_path, "07_block_sparse", "// Chapter 07: blocks.\nnamespace fem::ch07 {\n"
            "class BlockStepper : public Stepper {};\n}\n",
            {"work.hpp": "// Chapter 07's counts.\nint count_07();\n"})
    chapter(tmp_path, "08_element_kernels", "// Chapter 08: kernels.\nnamespace fem::ch08 {\n"
            "class KernelStepper : public Stepper {};\n}\n",
            {"work.hpp": "// Chapter 07's counts.\nint count_08();\n"})
    chapter(tmp_path, "12_half_the_bytes", "// Chapter 12: half the bytes.\n" + recipe("ch12"),
            {"parts.hpp": "// Chapter 12's parts.\nstruct Batched {};\n"})
    chapter(tmp_path, "13_fewer_waits", recipe("ch13", "ch12::Recipe"))
    chapter(tmp_path, "14_every_lane", "// Chapter 14: every lane.\n" +
            recipe("ch14", "fem::ch12::Recipe", ["12_half_the_bytes/stepper.hpp",
                                                 "12_half_the_bytes/parts.hpp"]),
            {"parts.hpp": "// Chapter 14's parts.\nstruct Lanes {};\n",
             "lane_scatter.cpp": "int scatter();\n"})
    return tmp_path / "chapters"


def test_a_recipe_builds_on_the_chapter_its_builds_on_names(course):
    assert parent_of(course / "14_every_lane") == course / "12_half_the_bytes"
    assert parent_of(course / "13_fewer_waits") == course / "12_half_the_bytes"


def test_a_chapter_without_builds_on_builds_on_the_chapter_before(course):
    assert parent_of(course / "08_element_kernels") == course / "07_block_sparse"
    assert parent_of(course / "07_block_sparse") is None


def test_a_variant_stands_where_its_original_stands(course):
    chapter(course.parent, "08_mine", recipe("ch08_mine"), {"variant_of": "08_element_kernels\n"})
    chapter(course.parent, "14_mine", recipe("ch14_mine", "ch12::Recipe"),
            {"variant_of": "14_every_lane\n"})
    assert parent_of(course / "08_mine") == course / "07_block_sparse"
    assert parent_of(course / "14_mine") == course / "12_half_the_bytes"
    # ... and is no chapter before another one.
    assert parent_of(course / "12_half_the_bytes") == course / "08_element_kernels"


def test_a_builds_on_of_no_chapter_is_refused(course):
    (course / "13_fewer_waits" / "stepper.hpp").write_text(recipe("ch13", "ch99::Nothing"))
    with pytest.raises(ValueError, match="ch99, the namespace of no chapter"):
        parent_of(course / "13_fewer_waits")


def test_the_diff_is_taken_against_the_parent_and_keeps_the_old_words(course):
    text = diffs.diff(parent_of(course / "14_every_lane"), course / "14_every_lane", course.parent)
    assert "--- chapters/12_half_the_bytes/stepper.hpp" in text
    assert "13_fewer_waits" not in text
    # The old text says "Chapter 12", as chapter 12's file does.
    assert "-// Chapter 12: half the bytes." in text
    assert "+// Chapter 14: every lane." in text
    # The code's names are the new chapter's on both sides: the namespace line is context.
    assert " namespace fem::ch14 {" in text


def test_a_part_of_the_same_name_as_the_parents_shows_as_added(course):
    text = diffs.diff(course / "12_half_the_bytes", course / "14_every_lane", course.parent)
    assert "--- /dev/null\n+++ chapters/14_every_lane/parts.hpp" in text
    assert "-struct Batched" not in text
    assert "--- /dev/null\n+++ chapters/14_every_lane/lane_scatter.cpp" in text


def test_a_recipe_copies_only_its_stepper(course):
    # 14 includes 12's parts.hpp; 13 includes nothing of 12's, yet its own parts are new files.
    (course / "13_fewer_waits" / "parts.hpp").write_text("struct Fused {};\n")
    assert diffs.copied_files(course / "12_half_the_bytes", course / "14_every_lane") == {"stepper.hpp"}
    assert diffs.copied_files(course / "12_half_the_bytes", course / "13_fewer_waits") == {"stepper.hpp"}


def test_a_copied_file_is_diffed_and_an_included_one_is_not(course):
    assert diffs.copied_files(course / "07_block_sparse", course / "08_element_kernels") == \
        {"stepper.hpp", "work.hpp"}
    text = diffs.diff(course / "07_block_sparse", course / "08_element_kernels", course.parent)
    assert "-int count_07();\n+int count_08();" in text
    # A chapter that includes its namesake extends it: its own file is new.
    (course / "08_element_kernels" / "work.hpp").write_text(
        '#include "chapters/07_block_sparse/work.hpp"\nint count_08();\n')
    assert diffs.copied_files(course / "07_block_sparse", course / "08_element_kernels") == \
        {"stepper.hpp"}
