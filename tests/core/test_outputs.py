"""Output paths are checked before any work: a clear error naming the path and the reason."""

import os

import pytest

from tg_drake.cli import COMMANDS, OUTPUTS, _parser, main
from tg_drake.errors import OutputError
from tg_drake.outputs import check_output_dir, check_output_file, prepare_output_dir


@pytest.fixture
def a_file(tmp_path):
    path = tmp_path / "a_file"
    path.write_text("keep me\n")
    return path


def test_a_folder_that_is_a_file_or_below_one_is_refused(a_file):
    with pytest.raises(OutputError, match=f"^{a_file}: the output folder is a file, not a folder"):
        check_output_dir(a_file)
    with pytest.raises(OutputError, match=f"{a_file} is a file, not a folder"):
        check_output_dir(a_file / "sub" / "dir")
    assert a_file.read_text() == "keep me\n"


def test_a_folder_on_a_virtual_file_system_is_refused():
    with pytest.raises(OutputError, match="^/proc: cannot write in the output folder: "
                                          "this file system does not hold files"):
        check_output_dir("/proc")
    with pytest.raises(OutputError, match="^/proc/tg_drake/x: the output folder cannot be made"):
        check_output_dir("/proc/tg_drake/x")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in a read-only folder")
def test_a_folder_without_write_permission_is_refused(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        with pytest.raises(OutputError, match="Permission denied"):
            check_output_dir(locked)
        with pytest.raises(OutputError, match="Permission denied"):
            check_output_dir(locked / "new")
    finally:
        locked.chmod(0o700)


def test_a_good_folder_is_checked_without_being_made_and_prepared_when_asked(tmp_path):
    new = tmp_path / "a" / "b"
    assert check_output_dir(new) == new
    assert not (tmp_path / "a").exists()  # a check leaves nothing behind
    assert prepare_output_dir(new) == new and new.is_dir()
    assert list(new.iterdir()) == []  # the write test removed its file


def test_output_files(tmp_path, a_file):
    with pytest.raises(OutputError, match=f"^{tmp_path}: the output file is a folder, not a file"):
        check_output_file(tmp_path)
    with pytest.raises(OutputError, match=f"^{a_file}/x.json: the output file cannot be written: "
                                          f"{a_file}: the folder is a file"):
        check_output_file(a_file / "x.json")
    with pytest.raises(OutputError, match="^/proc/x.json: the output file cannot be written"):
        check_output_file("/proc/x.json")
    assert check_output_file(a_file) == a_file and a_file.read_text() == "keep me\n"
    assert check_output_file(tmp_path / "new" / "x.json") == tmp_path / "new" / "x.json"
    assert not (tmp_path / "new").exists()


def test_every_command_that_writes_declares_its_output_paths():
    """A command whose parser has --out must say whether it is a folder or a file."""
    subparsers = next(a for a in _parser()._actions if a.dest == "command").choices
    for name in COMMANDS:
        dests = {a.dest for a in subparsers[name]._actions}
        if "out" in dests:
            assert "out" in OUTPUTS.get(name, {}), name
        assert set(OUTPUTS.get(name, {})) <= dests, name
    assert {kind for options in OUTPUTS.values() for kind in options.values()} <= {"file", "folder"}


@pytest.mark.parametrize("argv", [
    ["render", "{scenario}", "--out", "{file}"],
    ["run", "{scenario}", "--out", "{file}/below"],
    ["run", "{scenario}", "--out", "/proc/tg_drake"],
    ["eval", "{scenario}", "--out", "/proc"],
    ["eval", "{scenario}", "--out", "{tmp}", "--tables", "{file}"],
    ["bench", "--out", "{tmp}"],
])
def test_each_command_refuses_a_bad_out_before_any_work(argv, tmp_path, a_file, capsys):
    # The scenario does not exist: had the command started, the error would be about it.
    values = {"scenario": tmp_path / "missing.yaml", "file": a_file, "tmp": tmp_path}
    assert main([a.format(**values) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"tg-drake {argv[0]}: error: ")
    assert "--out" in err or "--tables" in err
    assert "missing.yaml" not in err


def test_run_checks_its_default_out_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out").write_text("")  # out/<scenario name> lies below a file
    assert main(["run", str(tmp_path / "missing.yaml")]) == 2
    assert "out/missing: the --out folder cannot be made: out is a file" in capsys.readouterr().err
