"""The course as a tree: which chapter each chapter builds on. From chapter 09 on a recipe names
its parent in its stepper.hpp, `using BuildsOn = chMM::RecipeName;` (chapter 14 builds on 12,
not 13); a chapter without that line (01-08, each a copy of the one before) builds on the
chapter before it in the course's order. The tools that set a chapter beside "the chapter before
it" (its diff, its comparisons) ask parent_of."""
import re

BUILDS_ON = re.compile(r"\busing\s+BuildsOn\s*=\s*(?:fem::)?(\w+)::\w+\s*;")
NAMESPACE = re.compile(r"namespace fem::(\w+) \{")


def course_chapters(root):
    """The course's chapters in order: a student's variant (./tutorial.sh variant, marked by
    its variant_of file) is no chapter of the course."""
    return sorted(d for d in (root / "chapters").iterdir()
                  if d.is_dir() and d.name[:2].isdigit() and (d / "stepper.hpp").exists()
                  and not (d / "variant_of").exists())


def namespace_of(chapter):
    """The chapter's namespace (fem::chNN), as its stepper.hpp opens it; None if it opens none."""
    match = NAMESPACE.search((chapter / "stepper.hpp").read_text())
    return match.group(1) if match else None


def parent_of(chapter):
    """The folder of the chapter `chapter` (a folder chapters/NN_name) builds on: the one whose
    namespace its BuildsOn names, else the course's chapter before it (a variant's: its
    original's); None for the first.
    Raises ValueError for a BuildsOn whose namespace is no chapter's."""
    chapters = chapter.parent
    match = BUILDS_ON.search((chapter / "stepper.hpp").read_text())
    if match:
        found = [d for d in sorted(chapters.iterdir())
                 if (d / "stepper.hpp").exists() and namespace_of(d) == match.group(1)]
        if not found:
            raise ValueError(f"{chapter.name}/stepper.hpp: BuildsOn names {match.group(1)}, "
                             "the namespace of no chapter")
        return found[0]
    variant_of = chapter / "variant_of"
    if variant_of.exists():  # a student's copy stands where its original stands
        return parent_of(chapters / variant_of.read_text().strip())
    before = [d for d in course_chapters(chapters.parent) if d.name < chapter.name]
    return before[-1] if before else None
