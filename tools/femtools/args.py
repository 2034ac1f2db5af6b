"""What every command's command line shares: its parser (the command's docstring as its help,
its name as `fem-tools GROUP COMMAND`), and the one --root of the commands that work on a
repository."""
import argparse
import pathlib

from femtools.paths import ROOT


def command_parser(prog, doc):
    return argparse.ArgumentParser(prog=prog, description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)


def add_root_option(parser, hidden=False):
    """--root: another checkout than this package's (a copy of the repository, as the tests make)."""
    parser.add_argument("--root", type=pathlib.Path, default=ROOT,
                        help=argparse.SUPPRESS if hidden else "the repository (default: this package's)")
