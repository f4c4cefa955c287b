"""Object pose on the table: upright, sideways or upside-down, with a likelihood.

Vertical versus horizontal symmetry axis comes from the completion (paper assumption f: the
direction of the axis gives the pose). Which end of the axis is the object's top uses these cues,
in order:

1. **Cavity.** An open container shows its inside through its opening: visible surface whose
   normal (oriented towards the camera, i.e. into free space) points *into* the object — towards
   the axis on an inner wall, or towards the opening on an inner bottom. The camera sees inside
   only through the opening, so the opening (the top) faces the camera: an upright object when
   the axis is vertical (the camera is above the table), the axis end on the camera's side when
   it is horizontal. This is the cue of an upright cup, glass, bowl, pan or open pot.
2. **Handle.** A handle at one end of the body marks the top: pans and pots carry their
   handles at the rim (a cup's handle spans the middle of its side and says nothing).
3. **Neck.** With no cavity seen, the top is closed. A top much narrower than the base over a
   body as wide as the base at mid-height is a neck: an upright bottle. A bottle whose shoulder
   begins below mid-height shows it by its wall (`shoulder`): straight in the lower half, then
   narrowing, where an upside-down container narrows from the table up.
4. **Taper.** A closed top narrower than the base otherwise, narrowing steadily from a rim on the
   table (already at mid-height, or strongly at the top: a can's rolled rim narrows only its last
   centimetre, and only a little), is the shape of a tapered open container (glass, cup, bowl,
   pan) resting on its rim: upside-down — when the side wall, where it is measured, narrows
   beyond its noise too (`taper_confirmed`: the end radii alone read noise at the base as a
   taper). Otherwise the closed end decides, and where it shows no shape (a flat end on a
   straight wall) the end radii do.
5. **Closed end.** A closed, straight end on top: a lid (upright) or the
   object's own base (upside-down), told by its shape rather than by the outline: a lid is
   recessed below a rim by a band of depths; a base is flat, or domed up from its centre (a
   can's bottom). `closed_end` measures the recess and the dome [m]; a logistic model fitted on
   perceived training views (`ClosedEndModel`, tools/calibrate_pose.py) reads a lid ("lid").
   A flat base looks like any flat closed top (a block's, a box's), so what the model reads as a
   base must show it by evidence other than the missing lid (`closed_end_decision`): the end
   pushed in beyond its noise ("base": a can's bottom), or the wall narrowing from the table up
   to the top beyond its noise (`wall_taper`, "rim": an open container rests on its rim, its
   wider end). A flat end on a straight wall ("flat") says nothing of which end it is by
   itself: the decision is the end the training views that reached it rested on more often
   (`PoseCalibration.flat_sign`: our containers' flat bases — a flat-topped solid standing is
   not among our categories; an upright can shows a recessed lid). Without enough
   points on the top (an open top seen from the side) or without a fitted model, the next cue
   decides.
6. Otherwise (closed and straight, like a can) the object is taken as upright: standing upright
   is the usual pose (the calibrated likelihood of this cue says how often that is wrong).

For a horizontal axis without a cavity or a handle at one end, the narrower end is the top (the
neck of a bottle lying down); equal ends keep the axis direction.

The likelihood is not set by hand: it is P(true pose | decision, cue) counted on perceived
views of the training objects (`PoseCalibration`, `tools/calibrate_pose.py`), so a cue that is
often wrong (a taper, a straight closed body) spreads its likelihood as often as it is wrong.
The thresholds of the cues (`PoseConfig`) were chosen on renders of our object library.
"""

from __future__ import annotations

import collections
import functools
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tg_drake.errors import PerceptionError
from tg_drake.perception.completion import Completion
from tg_drake.perception.config import PoseConfig
from tg_drake.types import POSES

# The likelihood of each pose given the decision and the cue that made it is calibrated, not set:
# `tools/calibrate_pose.py` perceives the training objects' views (the object-wise split's
# training set) through the default depth sensor and counts the true pose per (decision, cue);
# `PoseCalibration` turns the counts into probabilities. The shipped counts:
CALIBRATION_FILE = Path(__file__).resolve().parents[1] / "data" / "pose_likelihood.json"
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


# The closed end on top of a vertical object (`closed_end`): the top band holds the visible body
# points within END_BAND of the highest [m] (deeper than a recessed lid or a domed base); its
# centre the points within END_CENTRE of the end's radius from the axis, its middle band those
# between END_CENTRE and END_MIDDLE, its ring those beyond END_RING; each needs END_MIN_POINTS.
END_BAND = 0.02
END_CENTRE, END_MIDDLE, END_RING = 0.35, 0.6, 0.7
END_MIN_POINTS = 10
# The highest points of the ring: this quantile of their heights (a rim's crest, above the side
# wall's points in the band).
END_CREST_QUANTILE = 0.9
# A shape (a recess below the ring, a wall narrowing upwards) is told from noise when it exceeds
# this many standard errors (one-sided, about 0.1 % of flat ends or straight walls exceed it).
SHAPE_SIGNIFICANCE = 3.0
# The side wall (`wall_taper`): points whose normal is within 60° of horizontal, in this many
# height bins of at least this many points each.
WALL_NORMAL_COSINE = 0.5
# The end's own surface: points whose normal is within 60° of vertical.
UP_NORMAL_COSINE = 0.5
WALL_BINS = 8
WALL_MIN_POINTS = 8


@dataclass(frozen=True)
class ClosedEnd:
    """What the closed end on top of a vertical object shows (`closed_end`) [m]."""

    recess: float  # the ring's crest above the centre: a recessed lid, a domed base, 0 if flat.
    dome: float  # the middle band above the centre: a domed end's rise, 0 if flat.
    # The ring's median height above the centre's [m] and that difference's standard error [m]
    # (from the spread of the heights: the sensor's noise on the end itself). A flat end (a
    # solid's top, a container's flat base) has no rise beyond its noise; its crest (`recess`)
    # then measures only the noise's upper quantile.
    rise: float = 0.0
    rise_error: float = 0.0

    @property
    def shaped(self) -> bool:
        """The end is recessed below its ring beyond the noise (a lid below its rim, a base
        pushed in): its shape says which end it is. A flat end says nothing of that."""
        return self.rise > SHAPE_SIGNIFICANCE * self.rise_error

    def features(self) -> np.ndarray:
        """The closed-end model's features (`ClosedEndModel`): recess [mm], dome [mm] and
        recess² [mm²] (a lid is recessed by a band of depths: a flat base less, a domed one
        more)."""
        recess, dome = 1e3 * self.recess, 1e3 * self.dome
        return np.array([recess, dome, recess ** 2])


def closed_end(c: Completion, n_visible_T: np.ndarray | None = None) -> ClosedEnd | None:
    """The shape of the closed end on top of a vertical object from its visible points, or None
    when the top band shows too few points at the centre, in the middle or on the ring (an open
    top seen from the side, a narrow neck). With the visible points' normals `n_visible_T`, the
    ring's rise (`ClosedEnd.rise`) is measured on its upward-facing points only (the end's own
    surface, not the side wall's points in the band)."""
    vis = c.visible & ~c.handle
    p = c.p_T[vis]
    if len(p) < 3 * END_MIN_POINTS:
        return None
    z = p[:, 2]
    band = z > z.max() - END_BAND
    r = np.linalg.norm(p[band, :2] - c.p_TA[:2], axis=1)
    zb = z[band]
    facing_up = (np.ones(len(zb), bool) if n_visible_T is None else
                 n_visible_T[~c.handle[c.visible]][band, 2] > UP_NORMAL_COSINE)
    r_end = float(np.quantile(r, RADIUS_QUANTILE)) if len(r) else 0.0
    centre = r < END_CENTRE * r_end
    middle = (r >= END_CENTRE * r_end) & (r < END_MIDDLE * r_end)
    ring = r > END_RING * r_end
    if min(centre.sum(), middle.sum(), ring.sum()) < END_MIN_POINTS:
        return None
    z_centre = float(np.median(zb[centre]))
    top_ring = ring & facing_up
    if top_ring.sum() >= END_MIN_POINTS:
        rise = float(np.median(zb[top_ring])) - z_centre
        rise_error = float(np.hypot(_median_error(zb[centre]), _median_error(zb[top_ring])))
    else:  # no end surface on the ring: no shape seen
        rise, rise_error = 0.0, np.inf
    return ClosedEnd(recess=float(np.quantile(zb[ring], END_CREST_QUANTILE)) - z_centre,
                     dome=float(np.median(zb[middle])) - z_centre, rise=rise,
                     rise_error=rise_error)


def _median_error(x: np.ndarray) -> float:
    """Standard error of the median of `x` [its unit]: 1.253·σ/√n, σ from the median absolute
    deviation (1.4826·MAD, the normal's σ; robust to the few points of an edge)."""
    sigma = 1.4826 * float(np.median(np.abs(x - np.median(x))))
    return 1.2533 * sigma / np.sqrt(len(x))


@dataclass(frozen=True)
class WallTaper:
    """How the side wall of a vertical object narrows upwards (`wall_taper`): the slope of its
    radius against height, −dr/dz (> 0: narrower at the top), and its standard error."""

    narrowing: float  # [m/m]
    error: float  # [m/m]

    @property
    def significant(self) -> bool:
        """The wall narrows upwards beyond its noise: the object rests on its wider end."""
        return self.narrowing > SHAPE_SIGNIFICANCE * self.error


def wall_taper(c: Completion, n_visible_T: np.ndarray,
               between: tuple[float, float] = (0.0, 1.0)) -> WallTaper | None:
    """The visible side wall's narrowing upwards: the median radius (distance to the axis) of
    the wall's points (normal within WALL_NORMAL_COSINE of horizontal) in WALL_BINS height bins
    between the table and the top band, fitted by least squares against the bins' heights;
    None with fewer than three bins of WALL_MIN_POINTS points (a squat object, a hidden wall).
    `between`: the share of the wall's height range measured, from its lowest point (0) to its
    highest (1) — (0, 0.5) the lower half only.

    An open container upside down meets the table with its rim, which is (nearly always) its
    widest end: its wall narrows from the table up to the base on top. A solid standing on its
    base (a block, a cylinder) keeps its width. Unlike the taper cue's end radii (one quantile
    of each end's slice), the fit uses the whole wall and states its own noise, so it tells a
    draft of a few degrees from a straight wall."""
    vis = c.visible & ~c.handle
    p = c.p_T[vis]
    n = n_visible_T[~c.handle[c.visible]]
    if len(p) < WALL_MIN_POINTS:
        return None
    z = p[:, 2]
    wall = (np.abs(n[:, 2]) < WALL_NORMAL_COSINE) & (z < z.max() - END_BAND)
    if wall.sum() < 3 * WALL_MIN_POINTS:
        return None
    zw = z[wall]
    lo, hi = zw.min() + np.multiply(between, zw.max() - zw.min())
    wall[wall] = (zw >= lo) & (zw <= hi)
    if wall.sum() < 3 * WALL_MIN_POINTS:
        return None
    zw = z[wall]
    r = np.linalg.norm(p[wall, :2] - c.p_TA[:2], axis=1)
    edges = np.linspace(zw.min(), zw.max(), WALL_BINS + 1)
    k = np.clip(np.searchsorted(edges, zw, side="right") - 1, 0, WALL_BINS - 1)
    zs, rs, es = [], [], []
    for b in range(WALL_BINS):
        m = k == b
        if m.sum() >= WALL_MIN_POINTS:
            zs.append(float(np.median(zw[m])))
            rs.append(float(np.median(r[m])))
            es.append(max(_median_error(r[m]), 1e-5))
    if len(zs) < 3:
        return None
    zs, rs, w = np.array(zs), np.array(rs), 1.0 / np.array(es) ** 2
    zm = np.sum(w * zs) / w.sum()
    sxx = np.sum(w * (zs - zm) ** 2)
    slope = np.sum(w * (zs - zm) * (rs - np.sum(w * rs) / w.sum())) / sxx
    # The slope's error from the bins' scatter about the line (a wall that bends, or noise the
    # medians' errors understate), at least the one the bins' errors give.
    resid = rs - (np.sum(w * rs) / w.sum() + slope * (zs - zm))
    chi2 = float(np.sum(w * resid ** 2)) / max(len(zs) - 2, 1)
    return WallTaper(narrowing=-float(slope), error=float(np.sqrt(max(chi2, 1.0) / sxx)))


def shoulder(c: Completion, n_visible_T: np.ndarray) -> bool:
    """The side wall is straight in its lower half and narrows in its upper half, beyond their
    noise: a bottle's shoulder, however low it begins. An open container upside down (resting on
    its wider rim) narrows from the table up, its lower half too; a solid keeps its width."""
    lower = wall_taper(c, n_visible_T, (0.0, 0.5))
    upper = wall_taper(c, n_visible_T, (0.5, 1.0))
    if lower is None or upper is None or lower.significant:
        return False
    bend = upper.narrowing - lower.narrowing
    return bend > SHAPE_SIGNIFICANCE * float(np.hypot(upper.error, lower.error))


@dataclass(frozen=True)
class ClosedEndModel:
    """P(upside-down | a closed end on top): a logistic regression on `ClosedEnd.features` [mm],
    fitted on perceived views of the training objects (tools/calibrate_pose.py). A recessed
    flat lid says upright; a flat base or a domed one (a container's bottom) says upside-down."""

    weights: tuple[float, ...]  # one per feature [1/mm, 1/mm, 1/mm²]
    bias: float

    def p_upsidedown(self, end: ClosedEnd) -> float:
        x = float(np.dot(self.weights, end.features())) + self.bias
        return float(1.0 / (1.0 + np.exp(-x)))


def closed_end_decision(model: ClosedEndModel, end: ClosedEnd, wall: WallTaper | None, *,
                        narrower_top: bool = False, flat_sign: float = 1.0) -> tuple[float, str]:
    """(top sign, cue) of a closed end on top. The model reads the end's shape: a lid recessed
    below its rim says upright ("lid"). What it reads as a base must show it by more than the
    lack of a lid, since a flat closed top (a solid block's, a closed box's) looks like a flat
    base: the end is pushed in beyond its noise (a can's bottom: "base"), or the wall narrows
    from the table up (a container resting on its wider rim: "rim"). A flat end on a straight
    wall says nothing of which end is up: the end radii decide when they read the top narrower
    than the base (`narrower_top`: the taper cue the wall did not confirm, "taper"), else the
    end the training views that reached this cue rested on more often (`flat_sign`:
    `PoseCalibration.flat_sign`; "flat")."""
    if model.p_upsidedown(end) <= 0.5:
        return 1.0, "lid"
    if end.shaped:
        return -1.0, "base"
    if wall is not None and wall.significant:
        return -1.0, "rim"
    return (-1.0, "taper") if narrower_top else (flat_sign, "flat")


@dataclass(frozen=True)
class PoseCalibration:
    """Counts of the true pose among perceived training views, per (decision, cue) key
    ("upright/cavity", "sideways/tool", ...), and how many views' weight the prior has.

    The likelihood of a key is its counts smoothed towards the counts of its decision (all cues
    pooled), those towards uniform, each with `prior_views` pseudo-views: a key seen rarely
    says little more than its decision, one never seen says its decision's frequencies.
    """

    counts: dict = field(default_factory=dict)  # key → {pose: count}
    prior_views: float = 2.0  # [views] weight of the smoothing prior
    source: str = ""  # how the counts were made (objects, sensor, command)
    # The closed-end model (`ClosedEndModel`) fitted on the same views, or None (the cue off).
    closed_end: ClosedEndModel | None = None

    @property
    def flat_sign(self) -> float:
        """Which end is up when a closed end on top shows no shape and nothing else tells (the
        "flat" cue): +1 (upright) when the training views that reached the cue were upright at
        least as often as upside-down, else −1. A flat closed end is a solid's top or a
        container's base: the views count which our objects show; with none, upright."""
        seen = collections.Counter()
        for key, c in self.counts.items():
            if key.split("/")[1] == "flat":
                seen.update(c)
        return 1.0 if seen["upright"] >= seen["upsidedown"] else -1.0

    def likelihood(self, decision: str, cue: str) -> dict[str, float]:
        """P(true pose | decision, cue), over POSES (sums to 1)."""
        a = self.prior_views
        pooled = np.zeros(len(POSES))
        for key, c in self.counts.items():
            if key.split("/")[0] == decision:
                pooled += [c.get(p, 0) for p in POSES]
        p_decision = (pooled + a / len(POSES)) / (pooled.sum() + a)
        own = np.array([self.counts.get(f"{decision}/{cue}", {}).get(p, 0) for p in POSES],
                       float)
        p = (own + a * p_decision) / (own.sum() + a)
        return {k: float(v) for k, v in zip(POSES, p, strict=True)}


@functools.cache
def load_pose_calibration(path: str = "") -> PoseCalibration:
    """The calibration in `path` ("" = the shipped CALIBRATION_FILE); with no file at all, no
    counts (every likelihood uniform: what the calibration tool starts from)."""
    file = Path(path) if path else CALIBRATION_FILE
    if not file.is_file():
        if path:
            raise PerceptionError(f"no such pose calibration file {path!r}")
        return PoseCalibration()
    try:
        d = json.loads(file.read_text())
        end = d.get("closed_end")
        return PoseCalibration(
            counts=d["counts"], prior_views=float(d["prior_views"]), source=d.get("source", ""),
            closed_end=None if end is None else ClosedEndModel(
                weights=tuple(float(w) for w in end["weights"]), bias=float(end["bias"])))
    except (ValueError, KeyError, TypeError) as e:
        raise PerceptionError(f"{file}: not a pose calibration ({e})") from None


@dataclass
class PoseEstimate:
    pose: str  # the decision: the axis first (vertical or not), then which end is the top.
    likelihood: dict[str, float]  # POSES entry → probability (sums to 1).
    top_sign: float  # +1 when the object's top is at the positive end of the axis, else −1.
    cue: str  # the cue that placed the top: "cavity", "handle", "neck", "taper", "lid",
    # "base", "rim", "flat", "straight", or "ends".
    inward_points: int = 0  # visible body points whose normal points into the object ...
    inward_share: float = 0.0  # ... and their share of the visible body points.
    end: ClosedEnd | None = None  # the closed end on top, when the decision reached that cue ...
    wall: WallTaper | None = None  # ... and its side wall's narrowing upwards.
    narrower_top: bool = False  # the end radii read the top narrower than the base (taper cue)


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


def taper_confirmed(wall: WallTaper | None) -> bool:
    """The end radii's narrowing (the taper cue) is the wall's: where the side wall is measured
    (`wall_taper`), it narrows upwards beyond its noise. The end radii are one quantile of each
    end's slice, and the sensor's noise moves them: a straight can's base read 2–10 mm wider
    than its top on perceived views (D415 model). Without a measured wall (None: a squat
    object) the radii decide."""
    return wall is None or wall.significant


def tool_pose(c: Completion, cfg: PoseConfig | None = None) -> PoseEstimate:
    """A tool lies on the table: sideways, with the calibrated likelihood of that decision."""
    cfg = cfg or PoseConfig()
    return PoseEstimate("sideways", load_pose_calibration(cfg.calibration).likelihood(
        "sideways", "tool"), 1.0, "tool")


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
    first (vertical or horizontal), then the top end by the first cue that tells it. The
    likelihood is the calibrated P(true pose | decision, cue) (`PoseCalibration`).
    """
    cfg = cfg or PoseConfig()
    calibration = load_pose_calibration(cfg.calibration)
    end = wall = None
    vis = c.visible & ~c.handle
    p_vis = c.p_T[vis]
    inward = inward_facing(p_vis, n_visible_T[~c.handle[c.visible]], c.p_TA, c.axis_T)
    cavity = (inward.sum() >= cfg.min_cavity_points
              and inward.mean() >= cfg.min_cavity_share)
    r_low, r_mid, r_high = _profile_radii(c)
    # The taper cue's end radii: the top narrower than the base (steadily, or strongly at the top).
    narrower_top = bool(r_high < cfg.taper_ratio * r_low
                        and (r_mid < cfg.taper_body_ratio * r_low
                             or r_high < cfg.strong_taper_ratio * r_low))
    handle_end = _handle_end(c)
    if c.vertical:
        # The cue that places the top, and which end it says.
        if cavity:
            top_sign, cue = 1.0, "cavity"
        elif handle_end != 0:
            top_sign, cue = float(handle_end), "handle"
        elif r_high < cfg.neck_ratio * r_low and (r_mid >= cfg.neck_body_ratio * r_low
                                                  or shoulder(c, n_visible_T)):
            top_sign, cue = 1.0, "neck"
        elif narrower_top and taper_confirmed(wall := wall_taper(c, n_visible_T)):
            top_sign, cue = -1.0, "taper"
        else:  # the closed end (measured with or without a model: the calibration's input)
            end = closed_end(c, n_visible_T)
            if end is not None and not narrower_top:  # (with a narrower top: measured above)
                wall = wall_taper(c, n_visible_T)
            if end is not None and calibration.closed_end is not None:
                top_sign, cue = closed_end_decision(calibration.closed_end, end, wall,
                                                    narrower_top=narrower_top,
                                                    flat_sign=calibration.flat_sign)
            elif narrower_top:
                top_sign, cue = -1.0, "taper"
            else:
                top_sign, cue = 1.0, "straight"
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
    pose = "sideways" if not c.vertical else ("upright" if top_sign > 0 else "upsidedown")
    likelihood = calibration.likelihood(pose, cue)
    total = sum(likelihood.values())
    return PoseEstimate(pose, {k: likelihood[k] / total for k in POSES}, top_sign, cue,
                        int(inward.sum()), float(inward.mean()) if len(inward) else 0.0, end,
                        wall, narrower_top and c.vertical)
