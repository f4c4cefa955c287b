"""The result of a task's physical check, as result.json's ``task_outcome``."""

from __future__ import annotations

from dataclasses import dataclass, field

from tg_drake.types import TASKS


@dataclass(frozen=True)
class TaskOutcome:
    """Whether the executed task succeeded in physics, with its measure.

    `measure` holds the physical quantities the judgement was made on, e.g.
    ``{"poured_fraction": 0.85}`` or ``{"rest_pose": "upsidedown", "distance_m": 0.012}``.
    """

    task: str  # one of tg_drake.types.TASKS
    success: bool
    measure: dict = field(default_factory=dict)
    detail: str = ""

    def __post_init__(self):
        if self.task not in TASKS:
            raise ValueError(f"unknown task {self.task!r}; allowed: {', '.join(TASKS)}")

    def as_dict(self) -> dict:
        """result.json's ``task_outcome``: {task, success, measure, detail}."""
        return {"task": self.task, "success": bool(self.success),
                "measure": dict(self.measure), "detail": self.detail}
