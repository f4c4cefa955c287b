"""importing.frame: the object frame O, part labels, dimensions, grasp widths and cavity derived
from a bare mesh, checked on every shipped library object moved somewhere else: containers turned
about z and shifted; tools also stood on end and turned at random (they may be modelled so)."""

from __future__ import annotations

import functools
import math
import zlib

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tg_drake.errors import ModelError
from tg_drake.importing.frame import WALL_PRIOR, ObjectFrame, derive_frame
from tg_drake.objects import box_centre, load_library, mesh
from tg_drake.types import PART_LABELS

LIB = load_library()
IDS = list(LIB)
CONTAINERS = [i for i in IDS if not LIB[i].is_tool]
TOOLS = [i for i in IDS if LIB[i].is_tool]
OPEN = ("pan", "pot", "cup", "glass", "bowl")
HANDLE = PART_LABELS.index("handle")
# Poses the input is given in: containers stand upright (z up, as modelled); tools lie flat,
# stand on end (x up) or are turned at random.
POSES = {"container": ("upright",), "tool": ("lying", "standing", "random")}
MIN_AGREEMENT = 0.85  # share of vertices whose derived label is the shipped one (issue 18)


def _pose(obj_id: str, pose: str) -> np.ndarray:
    """X_MO: a random placement (seeded by the id) of the object frame in the input's frame M."""
    rng = np.random.default_rng(zlib.crc32(f"{obj_id}/{pose}".encode()))
    R = Rotation.from_euler("z", rng.uniform(0, 360), degrees=True).as_matrix()
    if pose == "standing":
        R = R @ Rotation.from_euler("y", -90, degrees=True).as_matrix()  # x_O up
    elif pose == "random":
        R = Rotation.random(random_state=int(rng.integers(2 ** 31))).as_matrix()
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = rng.uniform(-1.0, 1.0, 3)  # [m]
    return X


@functools.cache
def _derived(obj_id: str, pose: str, given_category: bool) -> tuple[ObjectFrame, np.ndarray]:
    """(the derived frame, T = X_OM · X_MO: shipped O → derived O; the identity when exact)."""
    V, F, _ = mesh(obj_id)
    X_MO = _pose(obj_id, pose)
    V_M = V @ X_MO[:3, :3].T + X_MO[:3, 3]
    fr = derive_frame(V_M, F, LIB[obj_id].category if given_category else None)
    return fr, fr.X_OM @ X_MO


def _cases(ids):
    return [(i, p) for i in ids for p in POSES["tool" if LIB[i].is_tool else "container"]]


@pytest.mark.parametrize("obj_id,pose", _cases(IDS))
def test_derived_labels_agree_with_the_shipped_ones(obj_id, pose):
    fr, _ = _derived(obj_id, pose, True)
    V, _, L = mesh(obj_id)
    assert fr.labels.shape == L.shape and fr.labels.dtype == np.uint8
    agreement = float(np.mean(fr.labels == L))
    assert agreement >= MIN_AGREEMENT, f"{obj_id} {pose}: {100 * agreement:.1f} % agree"
    assert set(fr.parts) == set(LIB[obj_id].parts)
    assert fr.kind == ("tool" if LIB[obj_id].is_tool else "container")


@pytest.mark.parametrize("obj_id", CONTAINERS)
def test_container_frame_is_the_shipped_one(obj_id):
    fr, T = _derived(obj_id, "upright", True)
    o = LIB[obj_id]
    # the axis stays vertical (input upright) and the origin is the bottom centre: within 2 mm
    # (the axis fit's scatter on a faceted wall is far below that)
    np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-9)
    np.testing.assert_allclose(T[:3, 3], 0.0, atol=0.002)
    if "handle" in o.parts:
        yaw = math.degrees(math.atan2(T[1, 0], T[0, 0]))
        if o.category == "pot":  # two opposite handles: either may be +x
            yaw = (yaw + 90.0) % 180.0 - 90.0
        assert abs(yaw) < 3.0, f"handle {yaw:.1f}° off +x"  # 3°: a tube handle's centroid


@pytest.mark.parametrize("obj_id,pose", _cases(TOOLS))
def test_tool_frame_is_the_shipped_one(obj_id, pose):
    fr, T = _derived(obj_id, pose, True)
    o = LIB[obj_id]
    # x lies in the plane the tool rests on. A flat tool lies along its length: x within 5° of
    # the shipped one. A round tool (a screwdriver) rests on its handle and its tip, so its shaft
    # tilts out of that plane, in any direction about the shaft since it may roll: by at most
    # the handle's radius over the half length (the handle's contact lies within its half,
    # the tip at the end), e.g. 10° for screwdriver_04 (measured: 5.2°).
    limit = 5.0
    if o.category == "screwdriver":
        V, _, _ = mesh(obj_id)
        yz = V[:, 1:]
        r_max = float(np.linalg.norm(yz - 0.5 * (yz.max(0) + yz.min(0)), axis=1).max())
        limit = math.degrees(math.atan(r_max / (0.5 * np.ptp(V[:, 0]))))
    assert T[0, 0] > math.cos(math.radians(limit)), \
        "x does not point from the handle to the usable area"
    if o.category != "screwdriver":  # a round tool rests on any side: any roll about x is right
        # Flat tools lie on either face (a half turn about x): z up to sign. 5°: the library
        # chose the resting facet with the true (heavier head) mass distribution, nearest the
        # model's −z; here the one holding a uniform-density centre of mass lowest.
        assert abs(T[2, 2]) > math.cos(math.radians(5.0))
        # the bounding box is the shipped one: its centre at (0, 0, half the thickness) in O,
        # within 3 mm across; 6 mm in height (such a tilt lifts a 0.3 m tool's box by that)
        c = T[:3, :3] @ box_centre(o) + T[:3, 3]
        np.testing.assert_allclose(c[:2], 0.0, atol=0.003)
        assert abs(c[2] - 0.5 * o.extents[2]) < 0.006
        assert abs(fr.dimensions["width"] - o.extents[1]) < 0.002  # 2 mm
        # the lowest-centre-of-mass facet lies at least as flat as the library's
        assert 0.5 * o.extents[2] < fr.dimensions["thickness"] < o.extents[2] + 0.001
    np.testing.assert_allclose(fr.dimensions["length"], o.extents[0], atol=0.002)


def _reach(obj_id: str) -> float:
    """[m] how far the shipped handle reaches out from the body's widest radius."""
    V, _, L = mesh(obj_id)
    return float(np.linalg.norm(V[L == HANDLE, :2], axis=1).max()
                 - 0.5 * LIB[obj_id].dimensions["diameter"])


@pytest.mark.parametrize("obj_id", CONTAINERS)
def test_container_dimensions_and_cavity(obj_id):
    fr, _ = _derived(obj_id, "upright", True)
    o, d = LIB[obj_id], fr.dimensions
    # 3 mm: library.yaml's height is the analytic crest of a rounded rim that the mesh's coarse
    # rim profile cuts up to 2.7 mm lower; the derived height is the mesh's
    assert abs(d["height"] - o.dimensions["height"]) < 0.003
    assert abs(d["diameter"] - o.dimensions["diameter"]) < 0.001  # 1 mm: faceting
    if o.category in OPEN:
        assert abs(d["wall"] - o.dimensions["wall"]) < 0.0005  # 0.5 mm
        assert abs(d["base"] - o.dimensions["base"]) < 0.0015  # 1.5 mm: a cut spacing + fillets
        # 3 %: the mesh's polygon and rim against the generator's analytic profile
        assert fr.cavity_volume == pytest.approx(o.cavity_volume, rel=0.03)
        np.testing.assert_allclose(fr.cavity_centroid, o.cavity_centroid, atol=0.002)
        assert fr.grasp_widths["top"] == pytest.approx(d["wall"])  # pinched across the rim
    else:
        # a closed body seen from outside: the wall is the category's prior; the cavity then
        # errs by about a shell of (true − prior) wall: glass bottles 3 mm, PET 0.4 mm → 15 %
        assert d["wall"] == WALL_PRIOR[o.category]
        assert fr.cavity_volume == pytest.approx(o.cavity_volume, rel=0.15)
        np.testing.assert_allclose(fr.cavity_centroid, o.cavity_centroid, atol=0.003)
    if "handle" in o.parts:
        # 8 mm: the reach is measured from the wall at the handle's root, here from the body's
        # widest radius (a flared pan's root lies up to 8 mm inside its rim)
        assert abs(d["handle_length"] - _reach(obj_id)) < 0.008
    for part, w in o.grasp_widths.items():
        assert abs(fr.grasp_widths[part] - w) < 0.002, part  # 2 mm: a mislabelled ring


@pytest.mark.parametrize("obj_id", TOOLS)
def test_tool_dimensions_and_grasp_widths(obj_id):
    fr, _ = _derived(obj_id, "lying", True)
    o, d = LIB[obj_id], fr.dimensions
    assert fr.cavity_volume is None and fr.cavity_centroid is None
    # Against the shipped handle's extent along x (library.yaml's handle_length of a ladle is
    # its curved handle's design length). 10 mm: the split falls in the gap between the handle's
    # last ring and the usable area's first (a knife's bolster, a spatula's widening neck).
    V, _, L = mesh(obj_id)
    assert abs(d["handle_length"] - np.ptp(V[L == HANDLE, 0])) < 0.010
    for part, w in o.grasp_widths.items():
        assert abs(fr.grasp_widths[part] - w) < 0.003, part  # 3 mm: a ring at the split


@pytest.mark.parametrize("obj_id,pose", [c for c in _cases(IDS) if c[1] != "random"])
def test_container_or_tool_from_the_shape(obj_id, pose):
    fr, _ = _derived(obj_id, pose, False)
    assert fr.kind == ("tool" if LIB[obj_id].is_tool else "container"), fr.notes[0]
    assert "category not given" in fr.notes[0]


def test_given_labels_are_used_and_checked():
    V, F, L = mesh("cup_01")
    mine = np.where(L == HANDLE, HANDLE, PART_LABELS.index("middle")).astype(np.int64)
    fr = derive_frame(V, F, "cup", labels=mine)
    np.testing.assert_array_equal(fr.labels, mine)
    assert fr.parts == ("middle", "handle")
    assert set(fr.grasp_widths) == {"middle", "handle"}
    assert any("given" in n for n in fr.notes)


@pytest.mark.parametrize("change,match", [
    (lambda V, F, L: (np.zeros((0, 3)), F, None), "vertices"),
    (lambda V, F, L: (V, np.zeros((0, 3), int), None), "faces"),
    (lambda V, F, L: (V, F + len(V), None), "face indices"),
    (lambda V, F, L: (np.where(np.arange(len(V))[:, None] == 3, np.nan, V), F, None), "NaN"),
    (lambda V, F, L: (V, F, L[:-1]), "part labels: .* values for .* vertices"),
    (lambda V, F, L: (V, F, np.where(np.arange(len(L)) == 0, 7, L)), "out of range"),
    (lambda V, F, L: (V, F, np.where(np.arange(len(L)) == 0, -1, L.astype(int))),
     "out of range"),
])
def test_bad_input_is_named(change, match):
    V, F, L = mesh("glass_01")
    V2, F2, L2 = change(np.array(V), np.array(F), np.array(L))
    with pytest.raises(ModelError, match=match):
        derive_frame(V2, F2, "glass", labels=L2)


def test_unknown_category_is_named():
    V, F, _ = mesh("glass_01")
    with pytest.raises(ModelError, match="unknown category 'mugg'; allowed: pan"):
        derive_frame(V, F, "mugg")


NOISY = ("cup_01", "glass_02", "bottle_01", "knife_02", "cooking_tool_01", "cooking_tool_02")
NOISE = 0.3e-3  # [m] std along the normal, as a hand-held scan's


@functools.cache
def _noisy(obj_id: str):
    """The object's mesh refined to 6 mm edges with Gaussian noise along the vertex normals, and
    each vertex's label from the nearest original vertex."""
    import trimesh
    from scipy.spatial import cKDTree

    V0, F0, L0 = mesh(obj_id)
    V, F = trimesh.remesh.subdivide_to_size(V0, F0, max_edge=0.006)
    m = trimesh.Trimesh(V, F, process=True)
    rng = np.random.default_rng(zlib.crc32(obj_id.encode()))
    V = m.vertices + m.vertex_normals * rng.normal(0.0, NOISE, (len(m.vertices), 1))
    return V, np.asarray(m.faces), L0[cKDTree(V0).query(m.vertices)[1]]


@pytest.mark.parametrize("obj_id", NOISY)
def test_a_noisy_fine_mesh_gives_the_same_frame(obj_id):
    V, F, L = _noisy(obj_id)
    o = LIB[obj_id]
    fr = derive_frame(V, F, o.category)
    assert np.mean(fr.labels == L) >= MIN_AGREEMENT
    if o.cavity_volume is not None and o.category in OPEN:
        # 3 %: medians of the noisy radii, not extremes
        assert fr.cavity_volume == pytest.approx(o.cavity_volume, rel=0.03)
        assert abs(fr.dimensions["wall"] - o.dimensions["wall"]) < 0.0005  # 0.5 mm
    assert derive_frame(V, F, None).kind == ("tool" if o.is_tool else "container")
