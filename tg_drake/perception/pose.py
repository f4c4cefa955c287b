"""Object pose on the table: upright, sideways or upside-down, with a likelihood.

Vertical versus horizontal symmetry axis comes from the completion (paper assumption f: the
direction of the axis gives the pose); its likelihood is the confidence of that decision
(`Completion.axis_margin`). Which end of the axis is the object's top uses these cues, in order:

1. **Cavity.** An open container shows its inside through its opening: visible surface whose
   normal (oriented towards the camera, i.e. into free space) points *into* the object — towards
   the axis on an inner wall, or towards the opening on an inner bottom. The camera sees inside
   only through the opening, so the opening (the top) faces the camera: an upright object when
   the axis is vertical (the camera is above the table), the axis end on the camera's side when
   it is horizontal. This is the cue of an upright cup, glass, bowl, pan or open pot.
2. **Handle.** A handle at one end of the body marks the top: pans and pots carry their
   handles at the rim (a cup's handle spans the middle of its side and says nothing).
3. **Neck.** With no cavity seen, the top is closed. A top much narrower than the base over a
   body as wide as the base at mid-height is a neck: an upright bottle.
4. **Taper.** A closed top narrower than the base otherwise, narrowing steadily from a rim on the
   table (already at mid-height, or strongly at the top: a can's rolled rim narrows only its last
   centimetre, and only a little), is the shape of a tapered open container (glass, cup, bowl,
   pan) resting on its rim: upside-down.
5. Otherwise (closed and straight, like a can) the object is upright with a weak likelihood:
   standing upright is the usual pose (the paper's S_GRASP and S_ROBOT scenes use only upright
   and sideways), and an upside-down straight container looks the same from above.

For a horizontal axis without a cavity or a handle at one end, the narrower end is the top (the
neck of a bottle lying down); equal ends keep the axis direction.

The thresholds of the cues (`PoseConfig`) were chosen on renders of our object library.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tg_drake.perception.completion import Completion
from tg_drake.perception.config import PoseConfig
from tg_drake.types import POSES

# P(upright) given each cue, for a vertical axis (see the module docstring).
P_UPRIGHT_CAVITY = 0.95
P_UPRIGHT_HANDLE = 0.85
P_UPRIGHT_NECK = 0.9
P_UPRIGHT_TAPER = 0.3
P_UPRIGHT_STRAIGHT = 0.6
# P(interior seen) when the inward-facing share says so: as sure as the cavity cue's P(upright).
P_INTERIOR = 0.95

# A visible normal points into the object when its cosine with the direction to the axis is above
# INWARD_WALL_COSINE (60°: an inner wall), or its cosine with the direction to the object's centre
# is above INWARD_CENTRE_COSINE (72°: an inner bottom, or a wall seen far from the centre). An
# outer surface of a convex shape has both cosines negative.
INWARD_WALL_COSINE = 0.5
INWARD_CENTRE_COSINE = 0.3
# End radii: this quantile of the distance to the axis among points in each end's slice.
RADIUS_QUANTILE = 0.95
# Each end's slice is this share of the object's length along the axis.
END_SLICE = 0.15
# A handle whose centroid lies in this share of the body's length next to one end is at that end
# (a pan's or pot's handle at the rim: 0.85–1.1 of the way up; a cup's spans 0.3–0.8: 0.5–0.55).
HANDLE_END = 0.4
# Two ends whose radii differ by less than this share are equal.
EQUAL_ENDS = 0.05


@dataclass
class PoseEstimate:
    pose: str  # the decision: the axis first (vertical or not), then which end is the top.
    likelihood: dict[str, float]  # POSES entry → probability (sums to 1).
    top_sign: float  # +1 when the object's top is at the positive end of the axis, else −1.
    cue: str  # the cue that placed the top: "cavity", "handle", "neck", "taper", "straight",
    # or "ends".
    inward_points: int = 0  # visible body points whose normal points into the object ...
    inward_share: float = 0.0  # ... and their share of the visible body points.


def inward_facing(p: np.ndarray, n: np.ndarray, p_A: np.ndarray, a: np.ndarray) -> np.ndarray:
    """(N,) bool: the normal points into the object: towards the axis (an inner wall), or back
    towards the object's centre p_A (an inner bottom seen through the opening)."""
    d = p - p_A
    s = d @ a
    r = d - np.outer(s, a)
    rho = np.linalg.norm(r, axis=1)
    radial = np.einsum("ij,ij->i", n, r) / np.maximum(rho, 1e-9)
    central = np.einsum("ij,ij->i", n, d) / np.maximum(np.linalg.norm(d, axis=1), 1e-9)
    return (radial < -INWARD_WALL_COSINE) | (central < -INWARD_CENTRE_COSINE)


def _profile_radii(c: Completion) -> tuple[float, float, float]:
    """Radii of the body (no handle) at the low end, the middle and the high end of the axis."""
    body = ~c.handle
    d = c.p_T[body] - c.p_TA
    s = d @ c.axis_T
    rho = np.linalg.norm(d - np.outer(s, c.axis_T), axis=1)
    lo, hi = s.min(), s.max()
    span = max(hi - lo, 1e-9)
    mid = 0.5 * (lo + hi)
    slices = (s < lo + END_SLICE * span, np.abs(s - mid) < 0.5 * END_SLICE * span,
              s > hi - END_SLICE * span)
    return tuple(float(np.quantile(rho[m], RADIUS_QUANTILE)) if m.any() else 0.0
                 for m in slices)


def _handle_end(c: Completion) -> int:
    """+1 (−1) when the handle sits at the high (low) end of the body along the axis, else 0."""
    if not c.handle.any():
        return 0
    s_body = (c.p_T[~c.handle] - c.p_TA) @ c.axis_T
    s_handle = float(np.mean((c.p_T[c.handle] - c.p_TA) @ c.axis_T))
    lo, hi = s_body.min(), s_body.max()
    f = (s_handle - lo) / max(hi - lo, 1e-9)
    return 1 if f > 1.0 - HANDLE_END else (-1 if f < HANDLE_END else 0)


def tool_pose(c: Completion) -> PoseEstimate:
    """A tool lies on the table: sideways, as sure as the axis (or, for a long-handled tool on
    its head, the circle test) is."""
    p = c.axis_margin if c.circle is None else max(c.axis_margin, c.circle.confidence)
    rest = 1.0 - p
    return PoseEstimate("sideways", {"upright": rest * P_UPRIGHT_STRAIGHT, "sideways": p,
                                     "upsidedown": rest * (1.0 - P_UPRIGHT_STRAIGHT)}, 1.0,
                        "tool")


def interior_seen(pose: PoseEstimate, is_tool: bool, cfg: PoseConfig | None = None) -> float:
    """Probability that the camera saw the object's inside through a wide opening (the
    `interior_seen` observation of the theory; 0 when it did not, or for a tool).

    The evidence is the cavity cue's: visible surface facing into the object. On depth images of
    our library from the S_REAL suite's viewpoint (`tg_drake.perception.render.perceive`: 44
    objects in each of their poses at yaws 0, 120, 240) its share of the visible body points is
    at most 0.06 on cans and bottles in any pose (a can's lid rim) and at least 0.17 on every
    upright glass, cup, bowl, pot and pan and every one lying with its opening towards the
    camera (0–0.01 facing away, 0 upside down); `min_interior_share` splits the two. The pose cue
    asks for more (`min_cavity_share`), since a wrong top end costs more than a missed sighting.
    """
    cfg = cfg or PoseConfig()
    if is_tool or pose.inward_points < cfg.min_cavity_points:
        return 0.0
    return P_INTERIOR if pose.inward_share >= cfg.min_interior_share else 0.0


def estimate_pose(c: Completion, n_visible_T: np.ndarray, p_TC: np.ndarray,
                  cfg: PoseConfig | None = None) -> PoseEstimate:
    """Pose of a completed object and its likelihood.

    Args:
        c: the completion (table frame T).
        n_visible_T: (V, 3) normals of the visible points, oriented towards the camera.
        p_TC: (3,) camera position in T [m].
        cfg: pose parameters.

    The pose is decided hierarchically, as the paper does (assumption f): the axis direction
    first (vertical or horizontal, with the axis decision's confidence), then the top end. The
    likelihood spreads each decision's uncertainty over the poses.
    """
    cfg = cfg or PoseConfig()
    vis = c.visible & ~c.handle
    p_vis = c.p_T[vis]
    inward = inward_facing(p_vis, n_visible_T[~c.handle[c.visible]], c.p_TA, c.axis_T)
    cavity = (inward.sum() >= cfg.min_cavity_points
              and inward.mean() >= cfg.min_cavity_share)
    r_low, r_mid, r_high = _profile_radii(c)
    handle_end = _handle_end(c)
    if c.vertical:
        if cavity:
            p_up, cue = P_UPRIGHT_CAVITY, "cavity"
        elif handle_end != 0:
            p_up, cue = (P_UPRIGHT_HANDLE if handle_end > 0 else 1 - P_UPRIGHT_HANDLE), "handle"
        elif r_high < cfg.neck_ratio * r_low and r_mid >= cfg.neck_body_ratio * r_low:
            p_up, cue = P_UPRIGHT_NECK, "neck"
        elif r_high < cfg.taper_ratio * r_low and (r_mid < cfg.taper_body_ratio * r_low
                                                   or r_high < cfg.strong_taper_ratio * r_low):
            p_up, cue = P_UPRIGHT_TAPER, "taper"
        else:
            p_up, cue = P_UPRIGHT_STRAIGHT, "straight"
        p_axis = c.axis_margin
        likelihood = {"upright": p_axis * p_up, "sideways": 1.0 - p_axis,
                      "upsidedown": p_axis * (1.0 - p_up)}
        top_sign = 1.0 if p_up >= 0.5 else -1.0
    else:
        if cavity:
            top_sign = 1.0 if (p_TC - c.p_TA) @ c.axis_T >= 0 else -1.0
            cue = "cavity"
        elif handle_end != 0:
            top_sign, cue = float(handle_end), "handle"
        elif abs(r_high - r_low) > EQUAL_ENDS * max(r_high, r_low):
            top_sign = 1.0 if r_high < r_low else -1.0
            cue = "neck"
        else:
            top_sign, cue = 1.0, "ends"
        p_axis = c.axis_margin
        rest = 1.0 - p_axis
        likelihood = {"upright": rest * P_UPRIGHT_STRAIGHT, "sideways": p_axis,
                      "upsidedown": rest * (1.0 - P_UPRIGHT_STRAIGHT)}
    total = sum(likelihood.values())
    pose = "sideways" if not c.vertical else ("upright" if top_sign > 0 else "upsidedown")
    return PoseEstimate(pose, {k: likelihood[k] / total for k in POSES}, top_sign, cue,
                        int(inward.sum()), float(inward.mean()) if len(inward) else 0.0)
