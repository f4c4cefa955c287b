"""The values the planner and the supervisor exchange: ``plan_request`` and ``plan_status``.

Kept apart from both systems so that the supervisor (whose config the scenario schema holds) does
not import the motion planner.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # for annotations only: the planner core imports the scenario schema
    from tg_drake.planning.planner import Plan


class PlanState(enum.StrEnum):
    """What the planner is doing (``PlanStatus.status``; compares equal to its value)."""

    planning = "planning"  # no plan yet, and no failure for the last attempt answered
    executing = "executing"  # a plan exists and is being followed
    done = "done"  # the plan's duration has passed
    failed = "failed"  # the last request has no plan: see `failed_part` and `reason`


@dataclass(frozen=True)
class PlanRequest:
    """Value of the ``plan_request`` input: plan attempt number `attempt` (1, 2, …; 0 = do not
    plan) without the candidates of `exclude_parts`. The planner answers each attempt once."""

    attempt: int = 0
    exclude_parts: tuple = ()
    regrasp: bool = False  # a place-and-regrasp's first leg may be planned (p&pIn*: the object
    # put down in an intermediate pose, `Plan.regrasp`), when the task's turn cannot be placed
    return_home: bool = False  # the plan ends with the arm back at its start configuration (out
    # of the camera's view), so that perception can look again after a missed grasp or lift
    reseats: int = 0  # re-seats asked for in the plan being executed: while its pads stand open
    # at the place, each one more makes the planner insert a re-seat (planning.planner.reseated)


@dataclass(frozen=True)
class PlanStatus:
    """Value of the ``plan_status`` output."""

    status: PlanState
    attempt: int = 0  # the request this status answers (0: none answered yet)
    part: str | None = None  # the chosen part
    candidate: int | None = None  # index of the chosen candidate in the ranked_grasps it came from
    X_WG: np.ndarray | None = None  # 4×4 chosen grasp pose
    unreachable_parts: tuple = ()  # parts of this attempt none of whose candidates can be picked
    picked_parts: tuple = ()  # parts of this attempt some candidate of which can be picked, though
    # no plan was found (placed, poured or handed over out of reach)
    reason: str = ""  # why the attempt failed (status "failed"), else ""
    planning_time: float = 0.0  # [s] wall time spent in the planner so far
    ik_solves: int = 0  # inverse-kinematics solver calls of the planner so far
    t_plan: float | None = None  # [s] simulated time at which the plan starts
    plan: Plan | None = None  # the plan itself (key times in plan time: add t_plan)
    reseats: int = 0  # the re-seats requests asked for that the plan now holds (or that came
    # too late to insert: after the pads' pause at the place)

    @property
    def failed_part(self) -> str | None:
        """The part that failed, or None when the failure blames no part (nothing left to try,
        or picked but not placed)."""
        return self.unreachable_parts[0] if self.unreachable_parts else None

    def __deepcopy__(self, memo):
        return self  # immutable: Drake's copies of abstract values may share it
