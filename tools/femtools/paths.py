"""Where the repository is. The package lives in tools/femtools/ of the repository it serves,
so every command reads and writes the tree it was run from: a copy of the repository (as the
coursework tests make) runs its own tools on itself."""
import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
TOOLS = ROOT / "tools"


def subcommand(*args):
    """The argv and environment that run `fem-tools ARGS` of this tree in a new process (its
    own package first on the path, whatever .venv has installed)."""
    path = os.pathsep.join(p for p in (str(TOOLS), os.environ.get("PYTHONPATH")) if p)
    return [sys.executable, "-m", "femtools", *map(str, args)], dict(os.environ, PYTHONPATH=path)
