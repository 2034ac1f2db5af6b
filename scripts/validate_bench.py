#!/usr/bin/env python3
"""Checks a results JSON against the schema documented in README.md.

    validate_bench.py results/bench.json
    validate_bench.py --scaling results/scaling.json
    validate_bench.py --regimes results/regimes.json
"""
import argparse
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from results_common import ResultsError, load, validate_bench, validate_scaling  # noqa: E402
from regimes_common import validate_regimes  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("json")
    parser.add_argument("--scaling", action="store_true", help="the file is a scaling.json")
    parser.add_argument("--regimes", action="store_true", help="the file is a regimes.json")
    args = parser.parse_args()
    try:
        data = load(args.json)
    except ResultsError as e:
        print(e, file=sys.stderr)
        return 1
    problems = (validate_scaling(data) if args.scaling else validate_regimes(data) if args.regimes
                else validate_bench(data))
    for p in problems:
        print(f"{args.json}: {p}", file=sys.stderr)
    if problems:
        return 1
    print(f"{args.json} valid")
    return 0


if __name__ == "__main__":
    sys.exit(main())
