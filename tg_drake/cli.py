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

from tg_drake import __version__
from tg_drake.errors import TgDrakeError
from tg_drake.outputs import check_output_dir, check_output_file

# command name → module implementing it.
COMMANDS: dict[str, str] = {
    "query": "tg_drake.logic.cli",
    "bench": "tg_drake.bench",
    "objects": "tg_drake.objects",
    "render": "tg_drake.render",
    "run": "tg_drake.run",
    "eval": "tg_drake.evaluation.cli",
    "import-object": "tg_drake.importing.cli",
    "cache": "tg_drake.importing.cache",
}

# command → an example for its --help (each runs from the repository's root).
EXAMPLES: dict[str, str] = {
    "query": "tg-drake query rules/examples/fig1_cup.yaml --json",
    "bench": "tg-drake bench --only sim_rtf --out bench.json",
    "objects": "tg-drake objects --json",
    "render": "tg-drake render scenarios/default.yaml --out out/render",
    "run": "tg-drake run scenarios/default.yaml --out out/default --meshcat",
    "eval": "tg-drake eval scenarios/suites/tiny.yaml --out out/tiny --workers 2",
    "import-object": ("tg-drake import-object mugs/blue_mug.obj --category cup --units auto "
                      "--up-axis z --mass 0.35 --out my_objects"),
    "cache": "tg-drake cache --prune-days 30",
}

# command → its options that name a path it writes, and whether each is a "folder" or a "file".
# Checked before the command starts, so a bad path is answered before any work.
OUTPUTS: dict[str, dict[str, str]] = {
    "bench": {"out": "file"},
    "render": {"out": "folder"},
    "run": {"out": "folder"},
    "eval": {"out": "folder", "tables": "folder", "export": "folder"},
    "import-object": {"out": "folder"},
}


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tg-drake", description="Task-dependent robot grasping in Drake.",
        epilog="exit status: 0 done, 1 the run failed or its task was not done, 2 bad input or "
        "usage", formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"tg-drake {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module_name in COMMANDS.items():
        module = importlib.import_module(module_name)
        p = sub.add_parser(name, help=module.HELP, description=module.HELP,
                           epilog=f"example:\n  {EXAMPLES[name]}",
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        module.add_arguments(p)
        p.set_defaults(_module=module)
    return parser


def check_outputs(args) -> None:
    """Checks every output path of the command, before it runs (tg_drake.outputs).

    A command whose output folder has a default computed from its other arguments gives it with
    `default_out(args)`.
    """
    for option, kind in OUTPUTS.get(args.command, {}).items():
        path = getattr(args, option)
        if path is None and option == "out" and hasattr(args._module, "default_out"):
            path = args._module.default_out(args)
        if path is None:
            continue
        what = f"--{option} {kind}"
        if kind == "file":
            check_output_file(path, what=what)
        else:
            check_output_dir(path, what=what)


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        check_outputs(args)
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
