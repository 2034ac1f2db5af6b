"""Which chapter's code runs each phase of each chapter's step, read from the sources: the table
between chapters/README.md's phase-owners markers (written by `fem-tools docs diffs`, checked by
its --check).

A chapter's step is its stepper class (stepper.hpp) and the chain of classes it derives from.
The phases are the blocks `{ PhaseTimer t(profile_.PHASE); ... }` of the step() in that chain
that times them. A call in a block runs:
  - a method some class of the chain declares `virtual` or `override`: the most derived class's
    definition (found in that class's chapter), and what that one calls in turn;
  - `Base::method(...)` of a class in the chain: that class's definition;
  - `chNN::function(...)`: chapter NN's function;
  - anything else: the code of the chapter whose body makes the call.
A class of the chain whose constructor calls use_preconditioner gives the solve its
preconditioner (the most derived one counts)."""
import re

from femtools.results.phases import ALL_PHASES

MARKER = "phase-owners"
CLASS = re.compile(r"\bclass\s+(\w+)\s+(?:final\s+)?:\s*public\s+(?:(ch\d\d\w*)::)?(\w+)")
COMMENT = re.compile(r"//[^\n]*")
NAME_BEFORE_PARENTHESIS = re.compile(r"(\w+)\s*\(")
PHASE_BLOCK = re.compile(r"\{\s*PhaseTimer\s+\w+\(profile_\.(\w+)\);")
QUALIFIED = re.compile(r"\b(ch\d\d)\w*::(\w+)\s*\(")
BASE_CALL = re.compile(r"\b(\w+)::(\w+)\s*\(")
CALL = re.compile(r"(?<![\w.>:])([A-Za-z]\w*[A-Za-z0-9])\s*\(")
PHASES = [p for p in ALL_PHASES if p != "step"]


def braced(text, start):
    """The text from the brace at or after `start` to its matching brace."""
    i = text.index("{", start)
    depth = 0
    for j in range(i, len(text)):
        depth += {"{": 1, "}": -1}.get(text[j], 0)
        if depth == 0:
            return text[i:j + 1]
    return text[i:]


def classes(chapter_dirs):
    """Every class with a public base in the chapters' headers: (chapter number, name) -> its
    chapter folder, its base's key and the methods it declares virtual or override. (A copied
    chapter keeps its classes' names: the chapter tells them apart.)"""
    found = {}
    for chapter in chapter_dirs:
        for header in sorted(chapter.glob("*.hpp")):
            text = COMMENT.sub("", header.read_text())
            for m in CLASS.finditer(text):
                declarations = re.split(r"[;{}]", braced(text, m.end())[1:])
                methods = {NAME_BEFORE_PARENTHESIS.search(d).group(1) for d in declarations
                           if re.search(r"\b(?:override|virtual)\b", d)
                           and NAME_BEFORE_PARENTHESIS.search(d)}
                base_number = m.group(2)[2:4] if m.group(2) else chapter.name[:2]
                found[(chapter.name[:2], m.group(1))] = {"chapter": chapter, "base": (base_number, m.group(3)),
                                                         "methods": methods}
    return found


def definition(info, cls, method):
    """The body of cls::method (cls a key of info) in its chapter's sources, or None."""
    pattern = re.compile(rf"\b{cls[1]}::{method}\s*\([^;{{}}]*\)[^;{{}}]*\{{")
    for path in sorted(info[cls]["chapter"].glob("*.[hc]pp")):
        text = COMMENT.sub("", path.read_text())
        m = pattern.search(text)
        if m:
            return braced(text, m.end() - 1)
    return None


class Owners:
    """The chapters whose code runs in one phase of one stepper's chain."""

    def __init__(self, info, chain, folders):
        self.info, self.chain, self.folders = info, chain, folders
        self.found, self.seen = {}, set()

    def add(self, chapter, what):
        listed = self.found.setdefault(chapter.name[:2], [])
        if what not in listed:
            listed.append(what)

    def owner(self, method):
        """The most derived class of the chain that declares method virtual or override."""
        return next((c for c in self.chain if method in self.info[c]["methods"]), None)

    def run(self, cls, method, depth):
        if (cls, method) in self.seen or depth > 6:
            return
        self.seen.add((cls, method))
        self.add(self.info[cls]["chapter"], f"`{method}`")
        body = definition(self.info, cls, method)
        if body is not None:
            self.calls(body, depth + 1)

    def calls(self, body, depth):
        for number, function in QUALIFIED.findall(body):
            if number[2:] in self.folders:
                self.add(self.folders[number[2:]], f"`{function}`")
        for name, method in BASE_CALL.findall(body):
            named = [i for i, c in enumerate(self.chain) if c[1] == name]
            if named:  # Base::method: the nearest definition from Base down
                defined = next((c for c in self.chain[named[0]:]
                                if definition(self.info, c, method) is not None), None)
                if defined is not None:
                    self.run(defined, method, depth)
        for method in CALL.findall(body):
            cls = self.owner(method)
            if cls is not None:
                self.run(cls, method, depth)


def chain_of(info, stepper):
    chain = []
    while stepper in info and stepper not in chain:
        chain.append(stepper)
        stepper = info[stepper]["base"]
    return chain


def phase_owners(info, stepper, folders):
    """Per phase, {chapter number: [what of it runs]} for the stepper class `stepper` (a key of
    info: its chapter's number and its name);
    folders: chapter number -> its folder."""
    chain = chain_of(info, stepper)
    timed = next((c for c in chain if (body := definition(info, c, "step")) and PHASE_BLOCK.search(body)),
                 None)
    if timed is None:
        return {}
    body = definition(info, timed, "step")
    marks = list(PHASE_BLOCK.finditer(body))
    result = {}
    for m in marks:
        block = braced(body, m.start())
        owners = Owners(info, chain, folders)
        owners.add(info[timed]["chapter"], "`step`")
        owners.calls(block, 1)
        result[m.group(1)] = owners.found
    preconditioned = next((c for c in chain
                           if "use_preconditioner(" in (definition(info, c, c[1]) or "")), None)
    if preconditioned and "solve" in result:
        result["solve"].setdefault(info[preconditioned]["chapter"].name[:2], []).append("its preconditioner")
    return result


def cell(owners):
    """The chapters of a phase, the latest first, each with what of it runs there."""
    return "; ".join(f"{n}: {', '.join(what)}" for n, what in sorted(owners.items(), reverse=True))


def owners_table(chapter_dirs, stepper_class):
    """The table: a row per chapter, a column per phase of StepProfile (the whole step left out)."""
    info = classes(chapter_dirs)
    folders = {d.name[:2]: d for d in chapter_dirs}
    rows = ["| chapter | " + " | ".join(PHASES) + " |", "| --- |" + " --- |" * len(PHASES)]
    for chapter in chapter_dirs:
        stepper = (chapter.name[:2], stepper_class(chapter))
        owners = phase_owners(info, stepper, folders) if stepper in info else {}
        rows.append(f"| {chapter.name[:2]} | " + " | ".join(cell(owners[p]) if p in owners else "none"
                                                           for p in PHASES) + " |")
    return "\n".join(rows) + "\n"
