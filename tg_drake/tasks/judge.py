"""The task judges: whether a task was done, from what physics left behind (pure functions).

Each takes what the supervisor reads off the station at the end of the plan (the object's world
pose, whether it is let go and on what it rests, where the contents' spheres are) and returns a
`TaskOutcome` with the physical measure it was judged on:

- p&pInUpright / p&pInSideways / p&pInUpsidedown (`judge_rest_pose`): let go and at rest, the
  object's pose classified from its simulated orientation is the task's pose, its box centre
  within `PLACE_XY_TOLERANCE` of the place target;
- p&pOn (`judge_on_surface`): let go, resting on the named surface's geometry (not on the table);
- pourOut / pourIn (`judge_pour`): at least `POUR_SUCCESS_FRACTION` of the spheres end in the
  receiving vessel (the bowl; the held container for pourIn), the container still held;
- pass (`judge_pass`): the receiver alone holds it `PASS_HOLD_DURATION` after the robot's release,
  its height steady within `PASS_HEIGHT_TOLERANCE`.
"""

from __future__ import annotations

import numpy as np

from tg_drake.outcome import CLOSED_ON_AIR, PLACE_XY_TOLERANCE, HandContact
from tg_drake.perception.ground_truth import pose_from_transform
from tg_drake.tasks.contents import ContentsModel, count_contents
from tg_drake.tasks.outcome import TaskOutcome

# The pose each placing task asks the object to rest in (an entry of tg_drake.types.POSES).
REST_POSE_OF_TASK = {"p&pInUpright": "upright", "p&pInSideways": "sideways",
                     "p&pInUpsidedown": "upsidedown"}
# [1] share of the spheres that must end in the receiving vessel for a pour to succeed.
POUR_SUCCESS_FRACTION = 0.8


def rest_pose(X_WO: np.ndarray, X_WT: np.ndarray, *, is_tool: bool) -> str:
    """The discrete pose (an entry of POSES) of an object at world pose X_WO (its library frame:
    z along the symmetry axis towards the opening) on the table X_WT: the library's one rule,
    `tg_drake.perception.ground_truth.pose_from_transform`."""
    return pose_from_transform(np.asarray(X_WO, float), np.asarray(X_WT, float), is_tool)


def judge_rest_pose(task: str, X_WO: np.ndarray, X_WT: np.ndarray, *, is_tool: bool,
                    p_WC: np.ndarray, target_xy, released: bool) -> TaskOutcome:
    """p&pIn*: the object at X_WO (true box centre `p_WC` in the world) rests let go
    (`released`) in the task's pose within `PLACE_XY_TOLERANCE` of `target_xy` (world)."""
    want = REST_POSE_OF_TASK[task]
    got = rest_pose(X_WO, X_WT, is_tool=is_tool)
    distance = float(np.linalg.norm(np.asarray(p_WC, float)[:2] - np.asarray(target_xy, float)))
    measure = {"rest_pose": got, "distance_m": round(distance, 4)}
    if not released:
        return TaskOutcome(task, False, measure, "not let go: still held, or not resting")
    if got != want:
        return TaskOutcome(task, False, measure, f"rests {got}, the task asks {want}")
    if distance > PLACE_XY_TOLERANCE:
        return TaskOutcome(task, False, measure,
                           f"rests {got} {distance * 100:.1f} cm from the target "
                           f"(> {PLACE_XY_TOLERANCE * 100:.0f} cm)")
    return TaskOutcome(task, True, measure, f"rests {got}, {distance * 100:.1f} cm from the target")


def judge_on_surface(surface: str, *, on_surface: bool, on_table: bool,
                     released: bool) -> TaskOutcome:
    """p&pOn: the object let go (`released`: the gripper does not hold it) touches the surface's
    geometry (`on_surface`) and not the table top's (`on_table`)."""
    measure = {"surface": surface, "on_surface": bool(on_surface), "on_table": bool(on_table)}
    if not released:
        return TaskOutcome("p&pOn", False, measure, "not let go: still held")
    if not on_surface:
        where = "on the table" if on_table else "on neither the surface nor the table"
        return TaskOutcome("p&pOn", False, measure, f"not on {surface}: {where}")
    if on_table:
        return TaskOutcome("p&pOn", False, measure,
                           f"touches both {surface} and the table (hanging over its edge)")
    return TaskOutcome("p&pOn", True, measure, f"resting on {surface}")


def judge_pour(task: str, counts: dict, *, into: str, held: bool) -> TaskOutcome:
    """pourOut / pourIn: `counts` (where every sphere is: `tg_drake.tasks.contents.
    count_contents`'s keys and counts) has at least `POUR_SUCCESS_FRACTION` of them in `into`
    (the bowl for pourOut, the held container for pourIn), and the container is still `held`."""
    total = int(sum(counts.values()))
    inside = int(counts.get(into, 0))
    fraction = inside / total if total else 0.0
    measure = {"poured_fraction": round(fraction, 4), "into": into, "counts": dict(counts)}
    if total == 0:
        return TaskOutcome(task, False, measure, "no contents to pour")
    if not held:
        return TaskOutcome(task, False, measure, "the container was not held to the end")
    ok = fraction >= POUR_SUCCESS_FRACTION
    return TaskOutcome(task, ok, measure,
                       f"{inside} of {total} spheres ({fraction:.0%}) in {into}"
                       + ("" if ok else f" (< {POUR_SUCCESS_FRACTION:.0%})"))


def contents_counter(model: ContentsModel, *, containers: dict, table_z: float):
    """body_poses → where the spheres of `model` are (`count_contents`), the containers given as
    name → (index of its body in body_poses, LibraryObject) [table_z: m, world]."""
    def count(body_poses) -> dict:
        return count_contents(model, body_poses, table_z=table_z, containers={
            name: (body_poses[index], obj) for name, (index, obj) in containers.items()})
    return count


# [m] pass: the object's height may change this much while the receiver holds it alone (its
# mount's PD sag under a 1 kg load is 0.5 mm; a slip in the pads shows as more).
PASS_HEIGHT_TOLERANCE = 0.01
PASS_HOLD_DURATION = 1.0  # [s] the receiver must hold it alone this long after the robot's release
# [s] the check time is a sum of the plan's segment times: it lands on the intended instant only
# up to floating-point rounding (seen: a 1 s hold measured as 1 s − 2e-15 s).
CLOCK_ROUNDING = 1e-9


def judge_pass(*, receiver: HandContact, robot_touches: bool, on_table: bool, z_W,
               held_for: float, hold_duration: float = PASS_HOLD_DURATION,
               tolerance: float = PASS_HEIGHT_TOLERANCE, receiver_part: str = "",
               received_part: str = "") -> TaskOutcome:
    """pass: `held_for` [s] after the robot let go, the receiver holds the object (`receiver`:
    its pads' contact; the one rule for "held", `tg_drake.outcome.is_held`: the object pushes
    both pads apart), it touches neither the robot's pads (`robot_touches`) nor the table
    (`on_table`), and its height, sampled from the release to now (`z_W` [m], world), stayed
    within `tolerance` [m]; `held_for` ≥ `hold_duration` [s]. `receiver_part`: the part the
    receiver was planned to take, and `received_part` the part its pads touch at the end
    (measured on the object's labelled mesh; "" when unknown): both reported, neither judged."""
    z = np.asarray(z_W, float).ravel()
    drift = float(np.ptp(z)) if len(z) else float("inf")
    held = receiver.held  # the one rule for "held"
    measure = {"receiver_held": held, "receiver_pads": [receiver.left, receiver.right],
               "receiver_squeeze_n": [round(receiver.squeeze_left, 2),
                                      round(receiver.squeeze_right, 2)],
               "receiver_opening_m": round(float(receiver.opening), 4),
               "robot_touches": bool(robot_touches), "on_table": bool(on_table),
               "height_change_m": round(drift, 4) if np.isfinite(drift) else None,
               "held_for_s": round(float(held_for), 3), "receiver_part": receiver_part,
               "received_part": received_part}
    if not held:
        pads = [n for n, t in (("left", receiver.left), ("right", receiver.right)) if not t]
        if pads:
            why = f"its {' and '.join(pads)} pad{'s' if len(pads) > 1 else ''} not touching"
        elif receiver.opening <= CLOSED_ON_AIR:
            why = (f"its fingers closed on air, the object pressing on their outsides or edges "
                   f"({receiver.describe()})")
        else:
            why = f"the object does not push both pads apart ({receiver.describe()})"
        where = " (it lies on the table)" if on_table else ""
        return TaskOutcome("pass", False, measure, f"the receiver does not hold it: {why}{where}")
    if robot_touches:
        return TaskOutcome("pass", False, measure, "the robot's pads still touch the object")
    if on_table:
        return TaskOutcome("pass", False, measure, "the object touches the table")
    if held_for < hold_duration - CLOCK_ROUNDING:
        return TaskOutcome("pass", False, measure,
                           f"held alone only {held_for:.2f} s (< {hold_duration} s)")
    if not drift <= tolerance:
        return TaskOutcome("pass", False, measure,
                           f"its height changed {drift * 1000:.0f} mm while the receiver held "
                           f"it (> {tolerance * 1000:.0f} mm): it slipped")
    by = f" by its {received_part.replace('_', ' ')}" if received_part else ""
    return TaskOutcome("pass", True, measure,
                       f"the receiver held it alone{by} {held_for:.1f} s, its height steady "
                       f"within {drift * 1000:.1f} mm")
