"""The command line: every command of the table is a module with a main, answers --help, and
a wrong group or command is a usage error (exit 2) that names the choices."""
import importlib
import inspect

import pytest

from femtools import cli

EVERY = [(g, c) for g, commands in cli.COMMANDS.items() for c in commands]


@pytest.mark.parametrize("group,command", EVERY)
def test_every_command_is_a_module_with_main(group, command):
    module = importlib.import_module("femtools." + cli.COMMANDS[group][command][0])
    assert list(inspect.signature(module.main).parameters) == ["argv", "prog"]


@pytest.mark.parametrize("group,command", EVERY)
def test_every_command_answers_help(group, command, capsys):
    with pytest.raises(SystemExit) as exit:
        cli.main([group, command, "--help"])
    assert exit.value.code == 0
    assert f"usage: fem-tools {group} {command}" in capsys.readouterr().out


def test_the_overview_lists_every_group_and_command(capsys):
    assert cli.main(["--help"]) == 0
    out = capsys.readouterr().out
    assert all(f"\n{g}:" in out for g in cli.COMMANDS)
    assert all(f"  {c} " in out for _, c in EVERY)


@pytest.mark.parametrize("argv,named", [(["nonsense"], "results, docs"), (["docs", "nonsense"], "update, lessons"),
                                        ([], "fem-tools GROUP COMMAND"), (["plots"], "bench")])
def test_a_wrong_or_missing_name_is_a_usage_error(argv, named, capsys):
    assert cli.main(argv) == 2
    assert named in capsys.readouterr().err
