"""stages/command.py: every stage's subcommands are whole (parser, handler, option keys that name options), unique,
and gathered into the command's parser, handlers and option limits in the order of the stages."""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import re

import pytest

import loper_analysis.cli as cli
from loper_analysis.cli_checks import OPTION_KEYS
from loper_analysis.cli_parser import SUBCOMMANDS
from loper_analysis.stages import STAGES
from loper_analysis.stages.command import Command, stage_commands


def _slices_commands() -> list[tuple[str, Command]]:
    """(stage, command) of every slice's ``command`` module, in the order of the stages."""
    found = []
    for stage in STAGES:
        name = f"loper_analysis.stages.{stage.name}.command"
        if importlib.util.find_spec(name) is not None:
            module = importlib.import_module(name)
            assert isinstance(module.COMMANDS, tuple) and module.COMMANDS, f"{name}: no COMMANDS"
            found += [(stage.name, c) for c in module.COMMANDS]
    return found


COMMANDS = _slices_commands()


def _parser(command: Command) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=command.name, exit_on_error=False)
    command.add_arguments(p)
    return p


def _value(action: argparse.Action) -> list[str]:
    """Command-line words giving ``action`` a valid value."""
    if action.nargs == argparse.REMAINDER:
        return []
    one = str(action.choices[0]) if action.choices else ("1" if action.type in (int, float) else "x")
    count = action.nargs if isinstance(action.nargs, int) else 1
    return [one] * count


def _required(p: argparse.ArgumentParser) -> list[str]:
    """The least command line ``p`` accepts: every positional and required option given a value."""
    argv = []
    for action in p._actions:
        if not action.option_strings:
            argv += _value(action)
        elif action.required:
            argv += [action.option_strings[0], *_value(action)]
    return argv


def test_the_stages_commands_are_gathered_in_the_order_of_the_stages():
    assert stage_commands() == tuple(c for _, c in COMMANDS)
    assert SUBCOMMANDS == (*(c.name for _, c in COMMANDS), "inspect")


def test_each_subcommand_name_is_unique_across_the_stages():
    names = [c.name for _, c in COMMANDS] + ["inspect"]
    assert len(names) == len(set(names)), names


@pytest.mark.parametrize("stage, command", COMMANDS, ids=[c.name for _, c in COMMANDS])
def test_a_command_is_whole_and_its_option_keys_name_its_options(stage, command):
    assert isinstance(command, Command) and command.help and callable(command.run), stage
    p = _parser(command)
    actions = {a.dest: a for a in p._actions}
    assert p.parse_args(_required(p)) is not None
    for option in command.option_keys:
        assert option in actions and actions[option].option_strings, f"{command.name}: no option {option}"
        argv = [*_required(p), actions[option].option_strings[0], *_value(actions[option])]
        assert getattr(p.parse_args(argv), option) is not None
    assert command.off_with_zero <= set(command.option_keys)


def test_the_parser_handlers_and_limits_come_from_the_commands():
    parser = cli.command_parser()
    for _, command in COMMANDS:
        args = parser.parse_args([command.name, *_required(_parser(command))])
        assert args.command == command.name and args.func is command.run
        assert OPTION_KEYS.get(command.name, {}) == dict(command.option_keys)


def test_the_commands_docstring_lists_the_subcommands_in_their_order():
    section = cli.__doc__.split("Subcommands\n-----------\n")[1].split("\n\n")[0]
    assert tuple(re.findall(r"^(\w+) ", section, re.M)) == SUBCOMMANDS
