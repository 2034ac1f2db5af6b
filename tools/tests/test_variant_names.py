"""A variant's name becomes a folder, a namespace and a target: a name that could break the
build (a newline among them, which a regular expression's $ lets through at the end) is refused
before anything is written."""
import pytest

from femtools.course import variant


@pytest.fixture
def root(tmp_path):
    chapter = tmp_path / "chapters" / "06_custom_pcg"
    chapter.mkdir(parents=True)
    (chapter / "stepper.hpp").write_text("namespace fem::ch06 {}\n")
    return tmp_path


@pytest.mark.parametrize("name", ["x\n", "a\nb", "\nx", "x\r", "x ", "a/b", "..", "Bad", "_x", "", "x\t",
                                  "-x", "a" * 300])
def test_an_unusable_name_is_refused_and_nothing_written(root, name):
    with pytest.raises(variant.VariantError, match="is not a variant name"):
        variant.make_variant(root, "06", name)
    assert [p.name for p in (root / "chapters").iterdir()] == ["06_custom_pcg"]


def test_a_usable_name_makes_the_copy(root):
    assert variant.make_variant(root, "06", "my_fused_updates") == ("06_custom_pcg", "06_my_fused_updates")
    assert (root / "chapters" / "06_my_fused_updates" / "variant_of").read_text() == "06_custom_pcg\n"


def test_a_name_like_an_option_reaches_the_check(root, capsys):
    """./tutorial.sh variant 06 -x passes the name after --: refused as a name, not as a
    missing argument."""
    assert variant.main(["--root", str(root), "--", "06", "-x"]) == 2
    assert "'-x' is not a variant name" in capsys.readouterr().err
