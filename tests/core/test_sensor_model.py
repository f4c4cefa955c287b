"""The depth sensor model on arrays: range² noise, grazing losses, edge shadows, seeding."""

import numpy as np
import pytest

from tg_drake.errors import PerceptionError
from tg_drake.perception.geometry import Intrinsics
from tg_drake.perception.sensor_model import (
    IdealDepth,
    StructuredLight,
    apply_sensor,
    incidence_cosine,
    shadow_mask,
)

# The scenario camera: 640×480, 45° vertical field of view (fx ≈ 579 px).
K = Intrinsics.from_fov(640, 480, np.deg2rad(45.0))


def plane_depth(normal_C, point_C, K=K) -> np.ndarray:
    """Exact depth image of the plane through point_C with normal normal_C (camera frame)."""
    n = np.asarray(normal_C, float)
    n /= np.linalg.norm(n)
    rays = K.ray_directions_C()
    with np.errstate(divide="ignore"):
        t = (n @ np.asarray(point_C, float)) / (rays @ n)
    return np.where(t > 0, t, np.inf).astype(np.float32)


@pytest.mark.parametrize("z", [1.0, 2.0, 3.0])
def test_axial_noise_is_the_stereo_formula(z):
    """On a frontal plane the measured depth's spread is z²·σ_d/(f·b) (within 10 %; 1 mm
    quantisation adds 0.3 mm in quadrature) and its mean stays at z."""
    model = StructuredLight()
    out = apply_sensor(np.full((K.height, K.width), z, np.float32), K, model, seed=3)
    v = out[20:-20, 20:-20].astype(float)
    v = v[v > 0]
    assert v.size > 0.99 * (K.height - 40) * (K.width - 40)
    expected = np.hypot(model.axial_rms(z, K.fx), model.depth_unit / np.sqrt(12))
    assert v.std() == pytest.approx(expected, rel=0.1)
    assert v.mean() == pytest.approx(z, abs=3 * expected / np.sqrt(v.size) + 1e-3)


def test_noise_grows_as_range_squared():
    """The fitted exponent of σ against z over 0.8–3.2 m is 2 (±0.1)."""
    model = StructuredLight(depth_unit=0.0, disparity_step=0.0)
    zs = np.array([0.8, 1.6, 3.2])
    sigmas = []
    for z in zs:
        out = apply_sensor(np.full((K.height, K.width), z, np.float32), K, model, seed=1)
        sigmas.append(out[out > 0].astype(float).std())
    slope = np.polyfit(np.log(zs), np.log(sigmas), 1)[0]
    assert slope == pytest.approx(2.0, abs=0.1)


def test_quantisation_steps():
    """Without noise, depths come out on the disparity grid and in whole output units."""
    model = StructuredLight(subpixel_rms=0.0, lateral_rms=0.0, depth_unit=0.001)
    z = np.linspace(0.5, 1.5, K.width, dtype=np.float32)[None, :].repeat(K.height, 0)
    out = apply_sensor(z, K, model).astype(float)
    v = out[out > 0]
    np.testing.assert_allclose(v / 0.001, np.rint(v / 0.001), atol=1e-3)
    assert np.abs(out - z)[out > 0].max() <= (1.5**2 * model.disparity_step
                                              / (K.fx * model.baseline) / 2 + 0.0005 + 1e-6)


def _centre_loss(incidence_deg: float) -> float:
    a = np.radians(incidence_deg)
    depth = plane_depth([0.0, -np.sin(a), -np.cos(a)], [0.0, 0.0, 1.0])
    cos = incidence_cosine(depth, K)
    window = (slice(K.height // 2 - 20, K.height // 2 + 20),
              slice(K.width // 2 - 20, K.width // 2 + 20))
    # The estimate from the image itself is the true incidence at the centre.
    assert np.degrees(np.arccos(cos[K.height // 2, K.width // 2])) == pytest.approx(
        incidence_deg, abs=0.5)
    out = apply_sensor(depth, K, StructuredLight(), seed=0)
    return float(np.mean(out[window] == 0))


def test_a_plane_seen_at_85_degrees_loses_its_pixels():
    assert _centre_loss(85.0) > 0.99


def test_a_plane_seen_at_45_degrees_keeps_its_pixels():
    assert _centre_loss(45.0) < 0.01


def _box_in_front(z_far=1.0, z_near=0.8):
    depth = np.full((K.height, K.width), z_far, np.float32)
    depth[150:330, 200:400] = z_near
    return depth


def test_an_edge_has_its_shadow_band_on_the_side_away_from_the_second_view():
    """The second view sits at +x (+u): background just left of a nearer box is hidden from it,
    over f·b·(1/z_near − 1/z_far) ≈ 8 px; right of the box nothing is hidden."""
    model = StructuredLight(lateral_rms=0.0)
    depth = _box_in_front()
    width = K.fx * model.baseline * (1 / 0.8 - 1 / 1.0)
    assert 7.0 < width < 9.0
    hidden = shadow_mask(depth, K, model.baseline)
    rows = slice(160, 320)
    assert hidden[rows, 200 - int(width):200].all()
    assert not hidden[rows, 200 - int(width) - 2].any()
    assert not hidden[rows, 400:].any()
    out = apply_sensor(depth, K, model, seed=0)
    assert (out[rows, 200 - int(width):200] == 0).all()
    assert (out[rows, 403:420] > 0).all()  # only the flying pixels at the right edge are lost
    # The box itself is measured.
    assert (out[rows, 205:395] > 0).all()


def test_the_band_changes_side_with_the_baseline():
    hidden = shadow_mask(_box_in_front(), K, -0.055)
    rows = slice(160, 320)
    assert hidden[rows, 400:407].all()
    assert not hidden[rows, :200].any()


def test_the_band_survives_lateral_noise():
    out = apply_sensor(_box_in_front(), K, StructuredLight(), seed=5)
    rows = slice(160, 320)
    assert np.mean(out[rows, 193:199] == 0) > 0.9
    assert np.mean(out[rows, 404:412] == 0) < 0.1


def test_same_seed_and_capture_give_the_same_image():
    depth = _box_in_front()
    a = apply_sensor(depth, K, StructuredLight(), seed=7, capture=2)
    b = apply_sensor(depth, K, StructuredLight(), seed=7, capture=2)
    np.testing.assert_array_equal(a, b)
    c = apply_sensor(depth, K, StructuredLight(), seed=7, capture=3)
    d = apply_sensor(depth, K, StructuredLight(), seed=8, capture=2)
    assert np.mean(a != c) > 0.3 and np.mean(a != d) > 0.3


def test_ideal_depth_is_the_image_itself():
    depth = _box_in_front()
    depth[0, 0] = np.inf
    np.testing.assert_array_equal(apply_sensor(depth, K, IdealDepth()), depth)


def test_no_return_stays_no_return_and_range_limits_apply():
    depth = np.full((K.height, K.width), np.inf, np.float32)
    depth[:, :320] = 0.1  # nearer than the D415's 0.16 m
    out = apply_sensor(depth, K, StructuredLight(), seed=0)
    assert not np.any((out > 0) & np.isfinite(out))


def test_bad_parameters_and_sizes_are_clear_errors():
    with pytest.raises(PerceptionError, match="baseline"):
        apply_sensor(_box_in_front(), K, StructuredLight(baseline=0.0))
    with pytest.raises(PerceptionError, match="camera info"):
        apply_sensor(np.ones((10, 10), np.float32), K, StructuredLight())
