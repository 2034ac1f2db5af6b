"""Each chapter is compared with the chapter it builds on: its recipe's BuildsOn from chapter 09
on (14 builds on 12, not 13), else the chapter before; the docs' tables follow it and say so
where it is not the chapter before."""
from femtools.course import parents
from femtools.docs import tables


def course(tmp_path, recipes):
    for name, text in recipes.items():
        (tmp_path / "chapters" / name).mkdir(parents=True)
        (tmp_path / "chapters" / name / "stepper.hpp").write_text(text)
    return tmp_path


def builds_on(number):
    return f"struct R {{\n  using BuildsOn = ch{number}::Recipe;  // the chapter this recipe changes\n}};\n"


def test_the_parent_is_the_recipes_builds_on_else_the_chapter_before(tmp_path):
    root = course(tmp_path, {"08_a": "", "09_b": builds_on("08"), "12_c": builds_on("09"),
                             "13_d": builds_on("12"), "14_e": builds_on("12")})
    (root / "chapters" / "14_mine").mkdir()
    (root / "chapters" / "14_mine" / "variant_of").write_text("14_e\n")
    (root / "chapters" / "14_mine" / "stepper.hpp").write_text(builds_on("12"))
    assert parents.parent_of(root, "08_a") is None
    assert parents.parent_of(root, "09_b") == "08_a"
    assert parents.parent_of(root, "14_e@2") == "12_c"
    assert parents.parent_of(root, "14_mine") == "12_c"
    assert parents.parent_of(root, "99_missing") is None
    assert parents.chapter_before(root, "14_e") == "13_d"
    assert parents.over(root, "14_e", "12_c@1") == " (its base)"
    assert parents.over(root, "13_d", "12_c") == ""


def test_without_builds_on_the_parent_is_the_chapter_before(tmp_path):
    root = course(tmp_path, {"01_a": "", "02_b": "", "03_c": "// using BuildsOn = chXX::Wrong;\n"})
    assert [parents.parent_of(root, c) for c in ("01_a", "02_b", "03_c")] == [None, "01_a", "02_b"]


def row(name, threads, step):
    return {"chapter": name, "threads": threads, "median_ms": {"step": step}}


def test_a_chapters_row_is_compared_with_its_base_at_the_same_thread_count(tmp_path):
    root = course(tmp_path, {"08_a": "", "09_b": builds_on("08"), "12_c": builds_on("09"),
                             "13_d": builds_on("12"), "14_e": builds_on("12")})
    data = {"chapters": [row("08_a", 1, 9.0), row("09_b@1", 1, 8.0), row("09_b@2", 2, 5.0),
                         row("12_c@1", 1, 4.0), row("12_c@2", 2, 2.0), row("13_d@1", 1, 5.0),
                         row("13_d@2", 2, 3.0), row("14_e@1", 1, 3.0), row("14_e@2", 2, 1.5)]}
    ref = {r["chapter"]: (tables.reference_row(root, data, r["chapter"]) or {}).get("chapter")
           for r in data["chapters"]}
    assert ref == {"08_a": None, "09_b@1": "08_a", "09_b@2": "09_b@1", "12_c@1": "09_b@1",
                   "12_c@2": "09_b@2", "13_d@1": "12_c@1", "13_d@2": "12_c@2",
                   "14_e@1": "12_c@1", "14_e@2": "12_c@2"}
    assert tables.over(root, "14_e@2", data["chapters"][4]) == "over `12_c@2` (its base)"
    assert tables.over(root, "13_d@2", data["chapters"][4]) == "over `12_c@2`"
    assert tables.base_note(root, "14_e@1", "12_c") == " `12_c` is its base (`BuildsOn`), not `13_d`."
    assert tables.base_note(root, "13_d@1", "12_c") == ""
