#!/usr/bin/env python3
"""Checks that ctest runs what the Catch2 test binaries contain: every test case of every
binary is registered exactly once, under its own name, with --warn NoAssertions (so a test
case that asserts nothing fails), and no ctest entry of a binary matches no test case (a ';'
in a name makes CMake split it in two, and each half then ran nothing and passed).

    check_registration.py --build-dir build/release --catch2-major 2 build/release/tests/test_common ...

The binaries are those registered with fem_catch_tests() in tests/CMakeLists.txt; every
tests/test_* executable of the build must be one of them."""
import argparse
import json
import pathlib
import subprocess
import sys

NO_ASSERTIONS = ["--warn", "NoAssertions"]
# What each Catch2 major version differs in here: the option that lists the test case names
# one a line, and the characters its CatchAddTests.cmake escapes with a backslash when it
# turns a name into a test spec (Catch2 3 escapes the backslash itself too).
LIST_NAMES = {2: ["--list-test-names-only"], 3: ["--list-tests", "--verbosity", "quiet"]}
ESCAPED = {2: ",[]", 3: "\\,[]"}


def unescape(spec, escaped=ESCAPED[2]):
    """The test name CatchAddTests.cmake escaped into a Catch2 test spec."""
    out, i = [], 0
    while i < len(spec):
        if spec[i] == "\\" and i + 1 < len(spec) and spec[i + 1] in escaped:
            i += 1
        out.append(spec[i])
        i += 1
    return "".join(out)


def problems_of(binary, case_names, entries, major=2):
    """entries: the ctest tests whose command runs `binary`, as (ctest name, command)."""
    problems = []
    registered = {}
    for name, command in entries:
        spec = unescape(command[1], ESCAPED[major]) if len(command) > 1 else ""
        if spec not in case_names:
            problems.append(f"ctest test '{name}' runs '{spec}', which is no test case of {binary}")
            continue
        if name != spec:
            problems.append(f"ctest test '{name}' runs the test case '{spec}' under another name")
        if not any(command[i:i + 2] == NO_ASSERTIONS for i in range(len(command))):
            problems.append(f"ctest test '{name}' runs without --warn NoAssertions "
                            "(register the binary with fem_catch_tests())")
        registered[spec] = registered.get(spec, 0) + 1
    for case in case_names:
        if ";" in case:
            problems.append(f"test case '{case}' of {binary}: a ';' splits the name in CMake")
        count = registered.get(case, 0)
        if count != 1:
            problems.append(f"test case '{case}' of {binary} is registered {count} times in ctest")
    return problems


def self_test():
    """The check itself must be able to fail: a split name and a missing flag are caught,
    and an escaped name is read back as each version's CatchAddTests.cmake wrote it."""
    cases = {"a; b", "c"}
    entries = [("a", ["bin", "a", *NO_ASSERTIONS]), (" b", ["bin", " b", *NO_ASSERTIONS]),
               ("c", ["bin", "c"])]
    found = problems_of("bin", cases, entries)
    expected = ["no test case", "no test case", "without --warn", "splits", "registered 0 times"]
    caught = all(any(e in p for p in found) for e in expected) and len(found) == len(expected)
    name = "x\\y, [z]"
    escaped = {2: "x\\y\\, \\[z\\]", 3: "x\\\\y\\, \\[z\\]"}
    read_back = all(not problems_of("bin", {name}, [(name, ["bin", escaped[m], *NO_ASSERTIONS])], m)
                    for m in (2, 3))
    return caught and read_back


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build-dir", type=pathlib.Path, required=True)
    parser.add_argument("--catch2-major", type=int, choices=sorted(LIST_NAMES), required=True,
                        help="the Catch2 the binaries were built with (its listing option)")
    parser.add_argument("binaries", nargs="+", type=pathlib.Path)
    args = parser.parse_args()
    if not self_test():
        print("the registration check's self-test failed", file=sys.stderr)
        return 1
    shown = subprocess.run(["ctest", "--test-dir", str(args.build_dir), "--show-only=json-v1"],
                           capture_output=True, text=True, check=True)
    tests = json.loads(shown.stdout)["tests"]
    binaries = {b.resolve() for b in args.binaries}
    problems = []
    for exe in sorted((args.build_dir / "tests").glob("test_*")):
        if exe.is_file() and exe.stat().st_mode & 0o111 and exe.resolve() not in binaries:
            problems.append(f"{exe} is not registered with fem_catch_tests()")
    total = 0
    for binary in sorted(binaries):
        listed = subprocess.run([str(binary), *LIST_NAMES[args.catch2_major]],
                                capture_output=True, text=True)
        case_names = {line for line in listed.stdout.splitlines() if line.strip()}
        entries = [(t["name"], t.get("command", [])) for t in tests
                   if t.get("command") and pathlib.Path(t["command"][0]).resolve() == binary]
        if not case_names:
            problems.append(f"{binary} lists no test case")
        problems += problems_of(binary.name, case_names, entries, args.catch2_major)
        total += len(case_names)
    for p in problems:
        print("FAIL", p)
    print(f"{total} test cases in {len(binaries)} binaries; {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
