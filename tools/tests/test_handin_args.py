"""The hand-in check's folder argument: '' as a path is the working directory, and the check
once read the repository as the hand-in (its .venv links reported as the student's)."""
import pytest

from femtools.course import handin


def test_an_empty_folder_name_is_refused():
    with pytest.raises(SystemExit, match="an empty folder name"):
        handin.main([""])
