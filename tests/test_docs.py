"""The repository documents itself: no tracked text file refers to a document outside it.

Docstrings, comments, docs and generated models once cited design notes and robot facts kept
beside the repository, which a user of the repository does not have. What they said is now in
docs/design.md, tg_drake/robot.py and tg_drake/table.py.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# Built from parts so that this file does not match itself.
OUTSIDE = ("DESIGN" + ".md", "robot_facts" + ".md", "../" + "shared", "/work/" + "shared")


def tracked_files(root: Path) -> list[Path]:
    """The files git tracks under `root` (skips the test when there is no git checkout)."""
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=root, capture_output=True,
                             check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout: the tracked files are unknown")
    return [root / name for name in out.decode().split("\0") if name]


def references_outside(paths) -> list[str]:
    """`path:line: text` for every line of a text file that names a document outside the
    repository (binary files, those holding a NUL byte, are skipped)."""
    found = []
    for path in paths:
        try:
            data = path.read_bytes()
        except OSError:  # tracked but deleted in the working tree
            continue
        if b"\0" in data:
            continue
        for n, line in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
            if any(ref in line for ref in OUTSIDE):
                found.append(f"{path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}"
                             f":{n}: {line.strip()}")
    return found


def test_no_tracked_file_refers_to_a_document_outside_the_repository():
    found = references_outside(tracked_files(ROOT))
    assert not found, ("refer to docs/design.md or say what the figure is instead:\n"
                       + "\n".join(found))


def test_the_check_finds_a_reference_outside(tmp_path):
    (tmp_path / "a.py").write_text('"""Wiring (' + OUTSIDE[0] + ', "The diagram")."""\n')
    (tmp_path / "b.sdf").write_text("<!-- from\n     " + OUTSIDE[2] + "/" + OUTSIDE[1] + " -->\n")
    (tmp_path / "c.md").write_text("See docs/design.md.\n")
    (tmp_path / "d.bin").write_bytes(b"\0" + OUTSIDE[1].encode())
    found = references_outside(sorted(tmp_path.iterdir()))
    assert [f.split(": ", 1)[0] for f in found] == [f"{tmp_path / 'a.py'}:1",
                                                     f"{tmp_path / 'b.sdf'}:2"]


def test_the_design_document_exists_and_is_linked_from_the_readme():
    assert (ROOT / "docs" / "design.md").is_file()
    assert "docs/design.md" in (ROOT / "README.md").read_text()


def test_the_design_documents_scenario_example_loads():
    from tg_drake.scenario import DepthPerception, DgiScorer, WsgPdDriver, load_scenario

    text = (ROOT / "docs" / "design.md").read_text()
    marker = "<!-- scenario example -->\n```yaml\n"
    assert marker in text, "docs/design.md lost its checked scenario example"
    example = text.split(marker, 1)[1].split("```", 1)[0]
    scenario = load_scenario(scenario_text=example)
    assert isinstance(scenario.pipeline.perception, DepthPerception)
    assert isinstance(scenario.pipeline.scoring, DgiScorer)
    assert isinstance(scenario.model_drivers["wsg"], WsgPdDriver)
    assert [o.id for o in scenario.objects] == ["cup_01"] and scenario.task.task == "pass"
    assert scenario.pipeline.supervisor.planning_timeout == 2.0
