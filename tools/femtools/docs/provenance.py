"""Where a table's numbers were recorded: the machine, the compiler and the commit, named in the
caption of every timed table (the README's promise), from the data themselves.

A run of fem_bench (bench.json, scaling.json, threads.json, regimes.json) records all three. A
lesson's file (docs/data/lessons/*.json) records its machine, and from issue 56 on its build and
commit too (fem_lessons); one recorded before that takes the compiler and the commit of the
book's sitting that lists it (docs/data/book.json, the file's hash equal to the listed one), from
that sitting's benchmark run (docs/data/bench.json, listed and equal too). Otherwise the caption
says what is not recorded."""
import hashlib
import json

from femtools.docs.book import MANIFEST

NOT_RECORDED = "not recorded"


def machine_name(machine):
    """The machine in a few words: its CPU and cores, "AMD EPYC (2 cores)"."""
    if not machine:
        return f"machine {NOT_RECORDED}"
    cpu = machine.get("cpu") or machine.get("model_name") or "an unnamed CPU"
    cores = machine.get("cores")
    return f"{cpu} ({cores} cores)" if isinstance(cores, int) and cores > 0 else cpu


def short_commit(commit, uncommitted=None):
    """The commit's first 7 digits, "-dirty" kept unless the record says that no measured source
    differed from it (uncommitted == []: git's --dirty also sees a changed README or data file)."""
    if not commit:
        return NOT_RECORDED
    dirty = commit.endswith("-dirty") and uncommitted != []
    return commit[:7] + ("-dirty" if dirty else "")


def describe(machine, compiler, commit, uncommitted=None):
    """ "AMD EPYC (2 cores), GNU 12.2.0, commit fa0a74e" """
    return (f"{machine_name(machine)}, {compiler or 'compiler ' + NOT_RECORDED}, "
            f"commit {short_commit(commit, uncommitted)}")


def of_run(data):
    """A benchmark run's own record (fem_bench's JSON, or the scaling and threads runs)."""
    return describe(data.get("machine"), (data.get("build") or {}).get("compiler"), data.get("commit"),
                    data.get("uncommitted"))


def _listed(root, manifest, name):
    path = root / name
    return path.exists() and manifest.get("data", {}).get(name) == hashlib.sha256(path.read_bytes()).hexdigest()


def lesson_build(root, path, data):
    """A lesson's file's compiler and commit: its own, or those of the book's sitting that lists
    it (None where neither records one)."""
    compiler, commit = (data.get("build") or {}).get("compiler"), data.get("commit")
    book = root / MANIFEST
    inside = path.resolve().is_relative_to(root.resolve())
    if (compiler is None or commit is None) and book.exists() and inside:
        manifest = json.loads(book.read_text())
        name = path.resolve().relative_to(root.resolve()).as_posix()
        bench = "docs/data/bench.json"
        if _listed(root, manifest, name) and _listed(root, manifest, bench):
            sitting = json.loads((root / bench).read_text())
            compiler = compiler or (sitting.get("build") or {}).get("compiler")
            commit = commit or sitting.get("commit")
    return compiler, commit


def of_lesson(root, path, data):
    return describe(data.get("machine"), *lesson_build(root, path, data), data.get("uncommitted"))
