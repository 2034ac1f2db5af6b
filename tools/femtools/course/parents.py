"""The chapter each chapter builds on: its recipe's parent. From chapter 09 on a recipe names it
in its stepper.hpp (`using BuildsOn = ch12::HalfTheBytes;`), and it need not be the chapter
before in order (chapter 14 builds on 12, not 13); chapters 01-08, which name none, build on the
chapter before. Every comparison the docs print of a chapter against another is against this
one, so that a chapter is not credited with, or charged for, a chapter it does not contain."""
import re

from femtools.docs.diffs import chapter_dirs
from femtools.results.common import chapter_dir

BUILDS_ON = re.compile(r"using BuildsOn = ch(\d\d)::")


def course_chapters(root):
    """The course's chapter folders in order, a student's variant left out (diffs.chapter_dirs)."""
    return [d.name for d in chapter_dirs(root)]


def parent_of(root, chapter):
    """The folder of the chapter `chapter` builds on ('14_every_lane' or a result row such as
    '14_every_lane@2' -> '12_half_the_bytes'); None for the first chapter or a folder unknown."""
    chapter = chapter_dir(chapter)
    stepper = root / "chapters" / chapter / "stepper.hpp"
    course = course_chapters(root)
    match = BUILDS_ON.search(stepper.read_text()) if stepper.exists() else None
    if match:
        named = [c for c in course if c[:2] == match.group(1)]
        if named:
            return named[0]
    before = [c for c in course if c < chapter and c[:2] != chapter[:2]]
    return before[-1] if before and stepper.exists() else None


def chapter_before(root, chapter):
    """The course's chapter before `chapter` in reading order (None for the first)."""
    before = [c for c in course_chapters(root) if c[:2] < chapter_dir(chapter)[:2]]
    return before[-1] if before else None


def over(root, chapter, parent):
    """"(its base)" when `chapter` builds on `parent` and that is not the chapter before it in
    order, so a reader of "over 12" under chapter 14 sees why it is not 13; else ""."""
    before = chapter_before(root, chapter)
    return " (its base)" if parent is not None and before is not None and \
        chapter_dir(parent) != before else ""
