"""Errors raised by tg_drake.

The input errors (scenario, model, perception, kernel, rule, grasping) are also `ValueError`s.

One root, `TgDrakeError`, with a typed child per concern. Each carries an optional location
(a file and, where known, a line or a field path) so that a user sees *where* the problem is.
"""

from __future__ import annotations


class TgDrakeError(Exception):
    """Root of every error tg_drake raises on purpose."""

    def __init__(self, message: str, *, file: str | None = None, line: int | None = None,
                 field: str | None = None):
        self.file = file
        self.line = line
        self.field = field
        where = []
        if file is not None:
            where.append(f"{file}:{line}" if line is not None else str(file))
        if field is not None:
            where.append(f"field '{field}'")
        prefix = (", ".join(where) + ": ") if where else ""
        super().__init__(prefix + message)
        self.message = message


class ScenarioError(TgDrakeError, ValueError):
    """A scenario file (or an object library entry it names) is malformed or inconsistent."""


class ModelError(TgDrakeError, ValueError):
    """A model file (robot, table, library object) is missing or malformed."""


class PerceptionError(TgDrakeError, ValueError):
    """Perception could not produce a scene description (empty cloud, no table plane, ...)."""


class KernelError(TgDrakeError, ValueError):
    """Bad input to the graph-kernel prior (too few points, missing normals, unknown labels)."""


class RuleError(TgDrakeError, ValueError):
    """Bad input to the probabilistic logic module (unknown name, bad probability, evidence of
    probability zero, a malformed theory)."""


class GraspingError(TgDrakeError, ValueError):
    """Bad input to the DGI grasp scoring (bad poses, unfitted model)."""


class PlanningError(TgDrakeError):
    """The planner could not produce a trajectory (no inverse-kinematics solution, collision)."""


class SimulationError(TgDrakeError):
    """The physics simulation failed (diverged, NaN state, solver failure)."""


class OutputError(TgDrakeError, ValueError):
    """An output path cannot be written (a file where a folder is needed, no permission, a
    read-only or virtual file system), or a results file to resume from is malformed."""


def unknown_name(kind: str, name: object, allowed, *, error: type[TgDrakeError], **where):
    """Builds the error for an unknown name, listing the allowed values (manipulation's style).

    Returns the exception; the caller raises it:
    `raise unknown_name("category", c, CATEGORIES, error=RuleError)` gives
    "unknown category 'mugg'; allowed: pan, pot, ...".
    """
    allowed = ", ".join(map(str, allowed))
    return error(f"unknown {kind} {name!r}; allowed: {allowed}", **where)
