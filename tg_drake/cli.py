"""The `tg-drake` command.

Each subcommand lives in the module that owns its work; this file only dispatches. A module listed
in COMMANDS provides `add_arguments(parser)` and `main(args) -> int` and a one-line `HELP`.
Command modules keep their heavy imports (pydrake, ProbLog, Open3D) inside functions, so building
the parser stays cheap.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from tg_drake.errors import TgDrakeError

# command name → module implementing it.
COMMANDS: dict[str, str] = {
    "query": "tg_drake.logic.cli",
    "bench": "tg_drake.bench",
    "objects": "tg_drake.objects",
    "render": "tg_drake.render",
    "run": "tg_drake.run",
    "eval": "tg_drake.evaluation.cli",
}


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tg-drake", description="Task-dependent robot grasping in Drake.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module_name in COMMANDS.items():
        module = importlib.import_module(module_name)
        p = sub.add_parser(name, help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        p.set_defaults(_module=module)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        return int(args._module.main(args) or 0)
    except TgDrakeError as e:
        print(f"tg-drake {args.command}: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (`tg-drake query x.yaml | head`): stop quietly, as Unix tools do,
        # and keep Python from reporting the closed pipe again when it flushes at exit.
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):  # stdout is not a file (a test's capture)
            pass
        return 141  # 128 + SIGPIPE, the shell's status for a command a pipe cut short


if __name__ == "__main__":
    sys.exit(main())
