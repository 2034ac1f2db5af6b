"""The course's Python tooling: one package, one command line (femtools.cli)."""
