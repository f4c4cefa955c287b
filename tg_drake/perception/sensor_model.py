"""What a real depth camera makes of a rendered depth image: a triangulating sensor's errors.

A renderer's depth image is exact to float precision, has a return on every surface however
grazing, and sees behind every edge. A triangulating camera — a stereo pair matching a projected
dot pattern (Intel RealSense D400) or a camera matching a projector's known pattern (structured
light, Kinect v1) — measures disparity d = f·b / z [px] between two viewpoints a baseline b apart,
and so:

- **Axial noise grows with range².** Disparity is matched to a sub-pixel RMS σ_d; z = f·b/d gives
  σ_z = z²·σ_d / (f·b) (Intel's depth RMS error formula).
- **Depth is quantised**: disparity to the matcher's sub-pixel step, depth to the output unit.
- **Lateral noise**: the matching window blurs where an edge lies, by a fraction of a pixel.
- **No return at grazing angles**: a surface seen at incidence θ (its normal against the ray)
  stretches the pattern by 1/cos θ across the matching window; beyond `max_incidence_deg` nothing
  matches. The normal is estimated from the depth image itself, so a depth discontinuity (whose
  "surface" runs along the ray) loses its flying pixels too.
- **A shadow band beside depth edges**: background that the depth (reference) view sees but the
  second viewpoint does not, hidden there by the nearer surface. It lies on the side of the nearer
  surface away from the second viewpoint and is f·b·(1/z_near − 1/z_far) pixels wide.

Every random draw is seeded by (seed, capture index), so one capture always gives one image.
Invalid pixels are 0 (a RealSense's "no depth"; Drake's depth images use 0 for too close and
+inf for too far: the perception stage skips both).

The camera frame is Drake's: X right, Y down, Z forward; the image column u grows with X.
(No `from __future__ import annotations` here: the scenario loader reads the field types.)
"""

from dataclasses import dataclass

import numpy as np

from tg_drake.errors import PerceptionError
from tg_drake.perception.geometry import Intrinsics


@dataclass
class IdealDepth:
    """The renderer's depth image as it is: exact depth, a return on every visible surface."""


@dataclass
class StructuredLight:
    """A triangulating depth camera (projected pattern matched across a baseline). The defaults
    are an Intel RealSense D415 (active IR stereo: a projected dot pattern matched between two
    imagers), the focal length in pixels being the scenario camera's own (the rendered image's
    intrinsics), so that the figures hold at the scenario's resolution.

    Sources: Intel RealSense D400 Series Product Family Datasheet (D415: baseline 55 mm, depth
    range 0.16 m to over 10 m, depth output in 1 mm units by default); A. Grunnet-Jepsen,
    J. Sweetser, J. Woodfill, "Tuning depth cameras for best performance" (Intel white paper):
    depth RMS error = z²·subpixel / (f·b), sub-pixel RMS about 0.08 px on a well-textured
    (pattern-lit) surface; Grunnet-Jepsen et al., "Subpixel linearity improvement for Intel
    RealSense depth cameras" (Intel white paper): disparity resolved to 1/32 px; C. V. Nguyen,
    S. Izadi, D. Lovell, "Modeling Kinect sensor noise for improved 3D reconstruction and
    tracking", 3DIMPVT 2012: lateral noise about 0.8 px, nearly independent of range, measured
    up to incidence angles of about 80° (no D415 figure for lateral noise is published).
    """

    name: str = "Intel RealSense D415"  # which camera these figures describe (for reports)
    baseline: float = 0.055  # [m] reference to second viewpoint, along the depth frame's +x
    # (negative: along −x); the D415's right imager sits at +x of its left (depth) imager
    subpixel_rms: float = 0.08  # [px] RMS disparity matching error
    disparity_step: float = 1.0 / 32.0  # [px] disparity quantisation (0: none)
    depth_unit: float = 0.001  # [m] output depth quantisation (0: none)
    lateral_rms: float = 0.8  # [px] RMS lateral displacement of a measured pixel (0: none)
    max_incidence_deg: float = 80.0  # [deg] no return from a surface seen more obliquely
    min_range: float = 0.16  # [m] no return nearer than this ...
    max_range: float = 10.0  # [m] ... or farther than this
    shadows: bool = True  # the second viewpoint's occlusion band beside depth edges

    def validate(self, where: str = "sensor") -> list[tuple[str, str]]:
        """(field, problem) for every value out of its physical range (empty: valid)."""
        checks = (("baseline", self.baseline != 0.0 and np.isfinite(self.baseline),
                   "a finite non-zero length [m]"),
                  ("subpixel_rms", self.subpixel_rms >= 0.0, ">= 0 px"),
                  ("disparity_step", self.disparity_step >= 0.0, ">= 0 px"),
                  ("depth_unit", self.depth_unit >= 0.0, ">= 0 m"),
                  ("lateral_rms", self.lateral_rms >= 0.0, ">= 0 px"),
                  ("max_incidence_deg", 0.0 < self.max_incidence_deg <= 90.0, "in (0, 90] deg"),
                  ("min_range", self.min_range >= 0.0, ">= 0 m"),
                  ("max_range", self.max_range > self.min_range, "> min_range [m]"))
        return [(f"{where}.{name}", f"must be {allowed}, got {getattr(self, name)}")
                for name, ok, allowed in checks if not ok]

    def axial_rms(self, z, fx: float):
        """σ_z [m] at depth z [m] for a focal length fx [px]: z²·σ_d / (f·|b|)."""
        return np.asarray(z, float) ** 2 * self.subpixel_rms / (fx * abs(self.baseline))


SensorModel = IdealDepth | StructuredLight


def capture_rng(seed: int, capture: int) -> np.random.Generator:
    """The generator of one capture: the same (seed, capture) always draws the same numbers."""
    return np.random.default_rng([int(seed) & 0xFFFFFFFF, int(capture) & 0xFFFFFFFF])


def _valid(depth: np.ndarray) -> np.ndarray:
    return np.isfinite(depth) & (depth > 0)


def incidence_cosine(depth: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """(H, W) |cos θ| between each pixel's ray and the surface normal estimated from the depth
    image (central differences of the back-projected points); NaN where a neighbour has no
    return or at the image border (no estimate)."""
    z = np.where(_valid(depth), depth, np.nan).astype(float)
    P = intrinsics.ray_directions_C() * z[..., None]
    du = np.full_like(P, np.nan)
    dv = np.full_like(P, np.nan)
    du[:, 1:-1] = P[:, 2:] - P[:, :-2]
    dv[1:-1] = P[2:] - P[:-2]
    n = np.cross(du, dv)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.abs(np.einsum("ijk,ijk->ij", n, P)) / (
            np.linalg.norm(n, axis=-1) * np.linalg.norm(P, axis=-1))
    return cos


def shadow_mask(depth: np.ndarray, intrinsics: Intrinsics, baseline: float) -> np.ndarray:
    """(H, W) bool: pixels the depth view sees but the second viewpoint, `baseline` [m] along the
    depth frame's x, does not (hidden there by a nearer surface of the same row).

    A point at column u with disparity d = fx·b / z appears in the second view at column u − d.
    It is hidden when some pixel farther along +u (for b > 0) lands at or beyond that column
    with a larger disparity: a running extremum of u − d along each row.
    """
    valid = _valid(depth)
    d = np.where(valid, intrinsics.fx * abs(baseline) / np.where(valid, depth, 1.0), 0.0)
    u = np.arange(depth.shape[1], dtype=float)[None, :]
    if baseline > 0:
        s = np.where(valid, u - d, np.inf)  # where each pixel lands in the second view
        # The least landing column among the pixels to the right of each pixel.
        right_min = np.minimum.accumulate(s[:, ::-1], axis=1)[:, ::-1]
        beyond = np.full_like(s, np.inf)
        beyond[:, :-1] = right_min[:, 1:]
        hidden = beyond < s - 0.5  # half a pixel: a surface does not hide itself
    else:
        s = np.where(valid, u + d, -np.inf)
        left_max = np.maximum.accumulate(s, axis=1)
        beyond = np.full_like(s, -np.inf)
        beyond[:, 1:] = left_max[:, :-1]
        hidden = beyond > s + 0.5
    return hidden & valid


def apply_sensor(depth: np.ndarray, intrinsics: Intrinsics, model: SensorModel, *,
                 seed: int = 0, capture: int = 0) -> np.ndarray:
    """The depth image `model` would measure of the scene whose exact depth is `depth`.

    Args:
        depth: (H, W) or (H, W, 1) exact depth along the optical axis [m] (+inf / 0: no return).
        intrinsics: the camera's pinhole intrinsics (image size must match).
        model: IdealDepth (the image is returned as it is) or StructuredLight.
        seed, capture: seed the draws (a scenario's random_seed and the image's capture index).

    Returns:
        float32 array of the input's shape [m], 0 where the sensor gives no depth (+inf kept where
        the input had no return and the sensor would not either).
    """
    depth = np.asarray(depth)
    shape = depth.shape
    if depth.ndim == 3 and shape[2] == 1:
        depth = depth[..., 0]
    if depth.shape != (intrinsics.height, intrinsics.width):
        raise PerceptionError(f"depth image is {depth.shape[::-1]} (width, height) but the camera "
                              f"info says ({intrinsics.width}, {intrinsics.height})")
    if isinstance(model, IdealDepth):
        return np.array(depth, np.float32).reshape(shape)
    if not isinstance(model, StructuredLight):
        raise PerceptionError(f"unknown sensor model {type(model).__name__}")
    problems = model.validate()
    if problems:
        raise PerceptionError("; ".join(f"{f}: {p}" for f, p in problems))
    rng = capture_rng(seed, capture)
    z = depth.astype(float)
    valid = _valid(z)
    lost = np.zeros_like(valid)
    # Grazing surfaces and flying pixels at depth edges: no pattern match.
    cos = incidence_cosine(z, intrinsics)
    lost |= valid & (cos < np.cos(np.radians(model.max_incidence_deg)))
    if model.shadows:
        lost |= shadow_mask(z, intrinsics, model.baseline)
    # Lateral noise: each pixel reports the scene (and its loss) at a displaced pixel.
    if model.lateral_rms > 0:
        h, w = z.shape
        rows = np.rint(np.arange(h)[:, None] + model.lateral_rms * rng.standard_normal((h, w)))
        cols = np.rint(np.arange(w)[None, :] + model.lateral_rms * rng.standard_normal((h, w)))
        rows = np.clip(rows, 0, h - 1).astype(int)
        cols = np.clip(cols, 0, w - 1).astype(int)
        z, valid, lost = z[rows, cols], valid[rows, cols], lost[rows, cols]
    # Axial noise and quantisation, in disparity.
    fb = intrinsics.fx * abs(model.baseline)
    zv = z[valid]
    d = fb / zv + model.subpixel_rms * rng.standard_normal(zv.shape)
    if model.disparity_step > 0:
        d = np.rint(d / model.disparity_step) * model.disparity_step
    with np.errstate(divide="ignore"):
        zn = np.where(d > 0, fb / np.maximum(d, 1e-12), np.inf)
    if model.depth_unit > 0:
        zn = np.rint(zn / model.depth_unit) * model.depth_unit
    out = np.array(z, float)
    out[valid] = zn
    out[valid & ((out < model.min_range) | (out > model.max_range))] = 0.0
    out[lost] = 0.0
    return out.astype(np.float32).reshape(shape)


def capture_index(t: float, fps: float, offset: float = 0.0) -> int:
    """The index of the latest frame a camera running at `fps` [Hz] from time `offset` [s] has
    captured by time `t` [s] (0 before the first; a millionth of a period of slack, so that a
    frame's own time counts as captured)."""
    if not fps > 0:
        raise PerceptionError(f"a camera's frame rate must be > 0 Hz, got {fps}")
    return max(0, int(np.floor((t - offset) * fps + 1e-6)))
