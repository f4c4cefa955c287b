"""Stable resting poses of an imported object (trimesh.poses.compute_stable_poses) and their names.

trimesh finds the convex-hull faces the object can rest on and the probability that it lands on
each when dropped in a random orientation. Each becomes X_TO (table-top frame T → object frame O)
as xyz + Drake's RollPitchYaw, resting on z = 0 with O's origin above T's origin and the smallest
rotation that puts the face down (so the yaw is that of the shipped library's poses). Names, by
where O's z points: containers `upright` (up), `upsidedown` (down), `sideways` (level); tools lie
flat with O's z up, which is their `sideways`. A pose further than MAX_TILT from these has no name.
Each name goes to its most probable pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.spatial import ConvexHull, QhullError

from tg_drake.objects import RestingPose

# A resting pose whose O z axis is further than this from the named direction has no name (the
# shipped library uses the same tolerance for "the face closest to down").
MAX_TILT = math.radians(35.0)
# [m] hull vertices this close to the table carry the object (the support polygon): scan noise
# and the table's compliance put a flat bottom's vertices within half a millimetre of it.
SUPPORT_TOL = 5e-4
# Poses less probable than this are dropped (a coin on its edge).
MIN_PROBABILITY = 0.01
# Poses within this fraction of the most probable one of their name are equally probable.
TIE = 0.1
# The shipped library's direction of the table in O per pose name (tools lie on -z).
DOWN = {"upright": np.array([0.0, 0.0, -1.0]), "upsidedown": np.array([0.0, 0.0, 1.0]),
        "sideways": np.array([0.0, -1.0, 0.0])}


@dataclass(frozen=True)
class StablePose:
    name: str | None  # "upright" | "sideways" | "upsidedown" | None
    probability: float
    resting: RestingPose  # X_TO; resting.pose is the name or "" when unnamed


def rot_to(n: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The smallest rotation taking unit vector n to unit vector target (a half turn about x, or
    y, when they are opposite)."""
    axis = np.cross(n, target)
    s, c = float(np.linalg.norm(axis)), float(n @ target)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        perp = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
        perp = perp - n * (perp @ n)
        perp /= np.linalg.norm(perp)
        return 2 * np.outer(perp, perp) - np.eye(3)
    k = axis / s
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    a = math.atan2(s, c)
    return np.eye(3) + math.sin(a) * K + (1 - math.cos(a)) * K @ K


def rpy_of(R: np.ndarray) -> tuple[float, float, float]:
    """Drake's RollPitchYaw (R = Rz(yaw)·Ry(pitch)·Rx(roll)) of a rotation matrix."""
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    if abs(math.cos(pitch)) < 1e-9:
        return (math.atan2(-R[1, 2], R[1, 1]), pitch, 0.0)
    return (math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0]))


def pose_name(z_T: np.ndarray, *, is_tool: bool) -> str | None:
    """The name of a resting pose whose O z axis points along z_T (unit, in T)."""
    up = float(z_T[2])
    if is_tool:
        return "sideways" if up >= math.cos(MAX_TILT) else None
    if up >= math.cos(MAX_TILT):
        return "upright"
    if up <= -math.cos(MAX_TILT):
        return "upsidedown"
    if abs(up) <= math.sin(MAX_TILT):
        return "sideways"
    return None


def support_margin(V_T: np.ndarray, com_T: np.ndarray) -> float:
    """[m] how far the COM projects inside the polygon of the vertices on the table (negative:
    outside; 0 for a support of fewer than three points in general position)."""
    low = V_T[V_T[:, 2] <= V_T[:, 2].min() + SUPPORT_TOL, :2]
    if len(low) < 3:
        return 0.0
    try:
        h = ConvexHull(low)
    except QhullError:
        return 0.0
    return float(-(h.equations[:, :2] @ com_T[:2] + h.equations[:, 2]).max())


def stable_poses(V: np.ndarray, F: np.ndarray, com: np.ndarray, *, is_tool: bool,
                 seed: int = 0) -> list[StablePose]:
    """Resting poses of the object (V, F, com in O [m]), most probable first, named."""
    m = trimesh.Trimesh(V, F, process=False)
    transforms, probs = trimesh.poses.compute_stable_poses(m, center_mass=com, sigma=0.0,
                                                          n_samples=1, seed=seed)
    hull_V = np.asarray(m.convex_hull.vertices)
    found = []
    for k, (X, p) in enumerate(zip(transforms, probs, strict=True)):
        if p < MIN_PROBABILITY and k > 0:  # (trimesh sorts them: the most probable stays)
            continue
        down_O = X[:3, :3].T @ np.array([0.0, 0.0, -1.0])  # the table's normal, into it, in O
        R = rot_to(down_O / np.linalg.norm(down_O), np.array([0.0, 0.0, -1.0]))
        z_T = R[:, 2]
        name = pose_name(z_T, is_tool=is_tool)
        if name == "upsidedown":  # a half turn about x, as the shipped library's, then the tilt
            Rx = np.diag([1.0, -1.0, -1.0])
            d = Rx @ down_O
            R = rot_to(d / np.linalg.norm(d), np.array([0.0, 0.0, -1.0])) @ Rx
        if is_tool and name == "sideways" and abs(down_O[2] + 1) < 1e-6:
            R = np.eye(3)
        V_T = hull_V @ R.T
        z = -float(V_T[:, 2].min())
        V_T[:, 2] += z
        com_T = R @ com + [0.0, 0.0, z]
        rest = RestingPose(name or "", (0.0, 0.0, round(z, 6) + 0.0),
                           tuple(round(a, 6) + 0.0 for a in rpy_of(R)),
                           round(support_margin(V_T, com_T), 4) + 0.0)
        found.append(StablePose(name, float(p), rest))
    found.sort(key=lambda s: -s.probability)
    # each name to its most probable pose; among poses about as probable (the strips of a round
    # wall), to the one whose down direction is the shipped library's for that name
    chosen = {}
    for name in {s.name for s in found} - {None}:
        same = [s for s in found if s.name == name]
        best = same[0].probability
        close = [s for s in same if s.probability >= (1 - TIE) * best]
        d = DOWN["upright"] if is_tool else DOWN[name]
        chosen[name] = min(close, key=lambda s, d=d: -float(_down_O(s.resting) @ d))
    out = []
    for s in found:
        if s.name is not None and chosen[s.name] is not s:
            s = StablePose(None, s.probability, RestingPose("", s.resting.xyz, s.resting.rpy,
                                                            s.resting.support_margin))
        out.append(s)
    return out


def _down_O(r: RestingPose) -> np.ndarray:
    return r.X_TO[:3, :3].T @ np.array([0.0, 0.0, -1.0])


def named_poses(poses: list[StablePose]) -> dict[str, RestingPose]:
    """name → RestingPose for the named ones, in POSES order of probability."""
    return {s.name: s.resting for s in poses if s.name is not None}
