"""The command line's own options: --version, Meshcat's interface and port."""

from __future__ import annotations

import os
import re
import socket
from pathlib import Path

import pytest

from tg_drake import __version__, cli
from tg_drake.errors import TgDrakeError
from tg_drake.run import start_meshcat


def test_version_prints_the_package_version(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"tg-drake {__version__}"


def _listening_addresses(port: int) -> set[str]:
    """Local addresses (hex, as /proc/net/tcp writes them) with a socket listening on `port`."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = open(table).read().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            local, state = line.split()[1], line.split()[3]
            address, port_hex = local.split(":")
            if state == "0A" and int(port_hex, 16) == port:  # 0A: LISTEN
                found.add(address)
    return found


def test_meshcat_listens_on_localhost_only_unless_asked():
    meshcat = start_meshcat()
    assert "localhost" in meshcat.web_url()
    addresses = _listening_addresses(meshcat.port())
    assert addresses, "Meshcat is not listening"
    loopback = {"0100007F", "00000000000000000000000001000000"}  # 127.0.0.1, ::1
    assert addresses <= loopback, addresses
    with socket.create_connection(("127.0.0.1", meshcat.port()), timeout=5):
        pass


def test_a_bad_or_taken_meshcat_port_is_a_clear_error():
    with pytest.raises(TgDrakeError, match=r"--meshcat-port must be a port number 1\.\.65535"):
        start_meshcat(port=70000)
    taken = start_meshcat()
    with pytest.raises(TgDrakeError, match=r"Meshcat cannot listen on --meshcat-host "
                                           r"'localhost' --meshcat-port \d+"):
        start_meshcat(port=taken.port())


def _help(command: str, capsys) -> str:
    with pytest.raises(SystemExit):
        cli.main([command, "--help"])
    return capsys.readouterr().out


def _readme_commands() -> dict[str, set[str]]:
    """command → the options the README's command table names for it."""
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    found = {}
    for m in re.finditer(r"^\| `tg-drake ([a-z-]+)([^`]*)` \|", readme, re.MULTILINE):
        found[m.group(1)] = set(re.findall(r"--[a-z][a-z-]*", m.group(2)))
    return found


def test_every_command_is_in_the_readme_and_its_help_has_an_example_and_the_readmes_options(
        capsys):
    readme = _readme_commands()
    assert set(readme) == set(cli.COMMANDS)
    for command, options in readme.items():
        text = _help(command, capsys)
        example = text.split("example:\n", 1)[1].split()
        assert example[:2] == ["tg-drake", command], command
        for option in options:
            assert option in text, (command, option)


def test_the_eval_progress_bar_names_the_suites():
    from tg_drake.evaluation.cli import progress_label
    assert progress_label(["scenarios/suites/s_grasp.yaml", "x/tiny.yaml"]) == "s_grasp, tiny"
    assert progress_label(["a.yaml"], (2, 4)) == "a [2/4]"
    assert progress_label([f"suite_number_{k}.yaml" for k in range(5)]) == "5 suites"


@pytest.mark.parametrize("status, task, code", [
    ("placed", None, 0), ("lifted", {"success": True}, 0), ("placed", {"success": False}, 1),
    ("failed", None, 1), ("failed", {"success": True}, 1)])
def test_run_exits_0_only_when_the_run_and_its_task_are_done(status, task, code):
    from tg_drake.run import exit_status
    result = {"outcome": {"status": status}, "task_outcome": task}
    assert exit_status(result) == code


def test_bench_writes_only_json_on_stdout_with_rounded_figures(capsys, monkeypatch):
    import json

    from tg_drake import bench
    monkeypatch.setitem(bench.FIGURES, "fake", "tests.core.test_command_line:_fake_figure")
    assert cli.main(["bench", "--only", "fake"]) == 0
    out = capsys.readouterr()
    data = json.loads(out.out)  # nothing but the JSON
    assert data["fake"]["median"] == 1.085 and data["fake"]["speedup"] == 1060.0
    assert "fake:" in out.err  # the progress line
    run = data["_run"]  # where and how: the figures are of one machine on one day
    assert run["command"] == "tg-drake bench --only fake" and run["cpus"] == os.cpu_count()
    assert run["wall_s"] >= 0 and run["versions"]["drake"]


def _fake_figure():
    from tg_drake.bench import figure
    return figure(1.084709496353753, "ms", "a reference", 1149.459994994686)
