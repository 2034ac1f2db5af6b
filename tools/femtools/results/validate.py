"""Checks a results JSON against the schema documented in README.md.

    fem-tools results validate results/bench.json
    fem-tools results validate --scaling results/scaling.json
    fem-tools results validate --regimes results/regimes.json
"""
import sys

from femtools.args import command_parser
from femtools.results.common import ResultsError, load
from femtools.results.schema import validate_bench, validate_scaling
from femtools.results.regimes import validate_regimes


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("json")
    parser.add_argument("--scaling", action="store_true", help="the file is a scaling.json")
    parser.add_argument("--regimes", action="store_true", help="the file is a regimes.json")
    args = parser.parse_args(argv)
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
