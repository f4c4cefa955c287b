"""The one place where the paper's names meet ProbLog atoms.

ProbLog atoms cannot contain '&' or start with a capital letter, so the paper's task names
(`tg_drake.types.TASKS`) and super-category names map to snake_case atoms here, and nowhere else.
Categories, parts, poses and containments are valid atoms already (`tg_drake.types`).
"""

from __future__ import annotations

from tg_drake.types import CATEGORIES, CONTAINMENTS, PART_LABELS, POSES, TASKS

# TASKS entry → ProbLog atom (rules/task_ontology.pl).
TASK_ATOMS: dict[str, str] = {
    "pass": "pass",
    "pourOut": "pour_out",
    "pourIn": "pour_in",
    "p&pInUpright": "pp_in_upright",
    "p&pInUpsidedown": "pp_in_upsidedown",
    "p&pInSideways": "pp_in_sideways",
    "p&pOn": "pp_on",
}
ATOM_TASKS: dict[str, str] = {atom: name for name, atom in TASK_ATOMS.items()}

# The paper's super-tasks and super-categories → atoms (rules/README.md).
SUPER_TASK_ATOMS: dict[str, str] = {"pour": "pour", "p&pIn": "pp_in", "place": "place"}
SUPER_CATEGORY_ATOMS: dict[str, str] = {
    "kitchenContainer": "kitchen_container",
    "dish": "dish",
    "openContainer": "open_container",
    "canister": "canister",
    "container": "container",
    "tool": "tool",
    "object": "object",
}

# Atom names equal the shared vocabulary for these; listed so that a theory check can assert it.
CATEGORY_ATOMS: tuple[str, ...] = CATEGORIES
PART_ATOMS: tuple[str, ...] = PART_LABELS
POSE_ATOMS: tuple[str, ...] = POSES
CONTAINMENT_ATOMS: tuple[str, ...] = CONTAINMENTS

# The constant that names the object under query in every observation and query atom.
OBJECT = "o"

assert set(TASK_ATOMS) == set(TASKS), "TASK_ATOMS must cover tg_drake.types.TASKS"
