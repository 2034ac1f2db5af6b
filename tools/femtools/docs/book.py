"""The book of this code: which sources the committed measurements were recorded from.

`./tutorial.sh book` records every measurement the docs show in one sitting, then runs
`fem-tools docs book manifest`, which writes docs/data/book.json: the commit, the machine, the sitting's
start and end, how long each stage took (the next sitting's estimate of the time left), a
SHA-256 of every file under docs/data/, and for every chapter a hash of its code: its
folder's sources together with every file they include from other chapters and from common/,
and the .cpp beside each included header (the code that runs, not only what is declared).

`fem-tools docs book check` fails when a data file was recorded outside that sitting
(its hash differs, or it is not listed), when the data files name other machines than the
sitting's, or when a chapter's code differs from the code its data were recorded from; it
names the chapter and the command that records the book again.

    fem-tools docs book manifest --started EPOCH --stages 'bench=123,lessons=456' [--root DIR]
    fem-tools docs book check [--root DIR]
    fem-tools docs book estimate [--root DIR]     # the last sitting's stage times, one 'name seconds' a line
    fem-tools docs book code-hash CHAPTER [...]   # the hash of one chapter's code, and the files it covers"""
import hashlib
import json
import pathlib
import re
import subprocess
import sys
import time

from femtools.args import add_root_option, command_parser


MANIFEST = pathlib.Path("docs/data/book.json")
INCLUDE = re.compile(r'^\s*#\s*include\s+"((?:chapters|common)/[^"]+)"', re.MULTILINE)
RECORD = "./tutorial.sh book"


def sha256(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def code_files(root, chapter):
    """The chapter's sources and, transitively, what they include from chapters/ and common/,
    with the .cpp beside every included header."""
    folder = root / "chapters" / chapter
    todo = sorted(p for p in folder.iterdir() if p.suffix in (".cpp", ".hpp"))
    seen = set()
    while todo:
        path = todo.pop()
        if path in seen or not path.exists():
            continue
        seen.add(path)
        for name in INCLUDE.findall(path.read_text(errors="replace")):
            included = root / name
            todo.append(included)
            todo.append(included.with_suffix(".cpp"))
    return sorted(p.relative_to(root).as_posix() for p in seen)


def code_hash(root, chapter):
    lines = "".join(f"{name} {sha256(root / name)}\n" for name in code_files(root, chapter))
    return hashlib.sha256(lines.encode()).hexdigest()


def chapters(root):
    return sorted(p.name for p in (root / "chapters").iterdir()
                  if (p / "stepper.hpp").exists() and not (p / "variant_of").exists())


def data_files(root):
    data = root / "docs" / "data"
    return sorted(p.relative_to(root).as_posix() for p in data.rglob("*.json")
                  if p.relative_to(root) != MANIFEST)


def git(root, *args):
    return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True).stdout.strip()


def machine_of(document):
    """The machine a JSON file names: its record's identity (the caches and memory say which
    machine; the load says only how busy it was)."""
    machine = document.get("machine") if isinstance(document, dict) else None
    if not isinstance(machine, dict):
        return None
    keys = ("vendor", "family", "model", "model_name", "isa_cpu", "cores", "hardware_threads")
    return {k: machine.get(k) for k in keys if k in machine} or None


def write_manifest(root, started, stages):
    machines = {}
    for name in data_files(root):
        identity = machine_of(json.loads((root / name).read_text()))
        if identity is not None:
            machines.setdefault(json.dumps(identity, sort_keys=True), []).append(name)
    if len(machines) != 1:
        sys.exit(f"book.py: the sitting's files name {len(machines)} machines, not one: "
                 + "; ".join(f"{m}: {', '.join(files)}" for m, files in machines.items()))
    manifest = {
        "commit": git(root, "rev-parse", "--short=12", "HEAD"),
        "uncommitted": [line[3:] for line in git(root, "status", "--porcelain").splitlines()
                        if line[3:].startswith(("chapters/", "common/", "apps/"))],
        "machine": json.loads(next(iter(machines))),
        "started": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(started)),
        "finished": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "stages": stages,
        "chapters": {c: code_hash(root, c) for c in chapters(root)},
        "data": {name: sha256(root / name) for name in data_files(root)},
    }
    path = root / MANIFEST
    temporary = path.with_suffix(".json.tmp")
    temporary.write_text(json.dumps(manifest, indent=1) + "\n")
    temporary.replace(path)
    print(f"book.py: wrote {MANIFEST} ({len(manifest['data'])} data files, "
          f"{len(manifest['chapters'])} chapters, {sum(stages.values()):.0f} s of stages)")


def problems(root):
    path = root / MANIFEST
    if not path.exists():
        return [f"{MANIFEST} is missing: the committed data come from no recorded sitting ({RECORD})"]
    manifest = json.loads(path.read_text())
    found = []
    listed = manifest.get("data", {})
    for name in data_files(root):
        if name not in listed:
            found.append(f"{name}: not recorded in the book's sitting ({RECORD} records it)")
        elif sha256(root / name) != listed[name]:
            found.append(f"{name}: changed since the book's sitting ({RECORD} records it again)")
        else:
            identity = machine_of(json.loads((root / name).read_text()))
            if identity is not None and identity != manifest.get("machine"):
                found.append(f"{name}: recorded on {identity}, the sitting on {manifest.get('machine')}")
    found += [f"{name}: recorded in the sitting, missing now" for name in listed
              if not (root / name).exists()]
    recorded = manifest.get("chapters", {})
    for chapter in chapters(root):
        if chapter not in recorded:
            found.append(f"chapter {chapter}: not measured in the book's sitting ({RECORD})")
        elif code_hash(root, chapter) != recorded[chapter]:
            found.append(f"chapter {chapter}: its code (its folder and what it includes) changed "
                         f"since the book's sitting at {manifest.get('commit')}; {RECORD} "
                         f"measures it again")
    found += [f"chapter {c}: in the book, no longer in chapters/" for c in recorded
              if c not in chapters(root)]
    return found


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__.split("\n\n")[0])
    add_root_option(parser)
    sub = parser.add_subparsers(dest="command", required=True)
    write = sub.add_parser("manifest", help="write docs/data/book.json after a sitting")
    write.add_argument("--started", type=float, required=True, help="the sitting's start (epoch s)")
    write.add_argument("--stages", default="", help="name=seconds,... the time of each stage")
    sub.add_parser("check", help="the committed data against the sitting and the code")
    sub.add_parser("estimate", help="the last sitting's stage times")
    one = sub.add_parser("code-hash", help="a chapter's code hash and the files it covers")
    one.add_argument("chapter", nargs="+")
    args = parser.parse_args(argv)
    root = args.root.resolve()
    if args.command == "manifest":
        stages = {k: float(v) for k, v in (s.split("=") for s in args.stages.split(",") if s)}
        write_manifest(root, args.started, stages)
    elif args.command == "check":
        found = problems(root)
        for line in found:
            print(f"FAIL {line}")
        print(f"fem-tools docs book check: {len(found)} problems" if found else
              "fem-tools docs book check: every data file is the sitting's, every chapter's code is what it measured")
        return 1 if found else 0
    elif args.command == "estimate":
        path = root / MANIFEST
        stages = json.loads(path.read_text()).get("stages", {}) if path.exists() else {}
        for name, seconds in stages.items():
            print(name, int(seconds))
    else:
        for chapter in args.chapter:
            print(chapter, code_hash(root, chapter))
            for name in code_files(root, chapter):
                print("  ", name)
    return 0

