"""The object library: meshes, part labels, mass, resting poses, surface sampling, the generator."""

from __future__ import annotations

import json
import subprocess
import sys
from argparse import Namespace
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from tg_drake.errors import ScenarioError
from tg_drake.objects import (
    get_object,
    library_by_category,
    load_library,
    main,
    mesh,
    sample_surface,
)
from tg_drake.robot import WSG_MAX_OPENING, WSG_PAD_SIZE
from tg_drake.types import CATEGORIES, PART_LABELS

LIB = load_library()  # the shipped, generated library: user libraries need not meet these rules
IDS = list(LIB)
TOOLS = ("hammer", "knife", "screwdriver", "cooking_tool")
OPEN = ("pan", "pot", "cup", "glass", "bowl")
REPO = Path(__file__).resolve().parents[2]

# Parts each category must have (section III-B of the paper): containers are cut in thirds along
# their axis, some have a handle; tools are a handle and a usable area.
REQUIRED = {c: {"top", "middle", "bottom"} for c in CATEGORIES if c not in TOOLS}
REQUIRED.update({c: REQUIRED[c] | {"handle"} for c in ("pan", "pot", "cup")})
REQUIRED.update({c: {"handle", "usable_area"} for c in TOOLS})

# Plausible masses [kg] of real products of each kind (empty): catalogue figures with a margin.
MASS_RANGE = {
    "pan": (0.4, 3.0), "pot": (0.4, 3.0), "cup": (0.1, 0.5), "glass": (0.08, 0.5),
    "bowl": (0.1, 0.8), "bottle": (0.015, 0.8), "can": (0.008, 0.12), "hammer": (0.25, 1.2),
    "knife": (0.04, 0.35), "screwdriver": (0.03, 0.25), "cooking_tool": (0.03, 0.4),
}
# Densities [kg/m³] of the materials of single-material objects (handbook values).
DENSITY = {"ceramic": 2400.0, "glass": 2500.0, "steel": 7900.0, "aluminium": 2700.0,
           "cast_iron": 7200.0, "plastic": 1100.0, "pet": 1380.0}

GRIPPER_OPENING = WSG_MAX_OPENING  # [m] WSG 50 full stroke.
CLEARANCE = 0.005  # [m] per side, to slide the fingers around the part.
FINGER_THICKNESS = WSG_PAD_SIZE[0]  # [m] a pad (with tip) along the closing direction.


def mesh_volume(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


def winding_number(V, F, q):
    """Generalised winding number of a closed mesh at query points q (1 inside, 0 outside)."""
    a = V[F[:, 0]][None] - q[:, None]
    b = V[F[:, 1]][None] - q[:, None]
    c = V[F[:, 2]][None] - q[:, None]
    la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
    num = np.einsum("qfi,qfi->qf", a, np.cross(b, c))
    den = (la * lb * lc + np.einsum("qfi,qfi->qf", a, b) * lc
           + np.einsum("qfi,qfi->qf", b, c) * la + np.einsum("qfi,qfi->qf", c, a) * lb)
    return np.arctan2(num, den).sum(1) / (2 * np.pi)


def test_library_covers_every_category_with_four_or_more_objects():
    by_cat = library_by_category()
    assert list(by_cat) == list(CATEGORIES)
    assert all(len(objs) >= 4 for objs in by_cat.values()), {c: len(o) for c, o in by_cat.items()}
    assert len(LIB) == sum(len(o) for o in by_cat.values()) >= 44
    # instances of a category differ in size: no two share their bounding box to 2 mm
    for objs in by_cat.values():
        ext = np.array([o.extents for o in objs])
        d = np.abs(ext[:, None] - ext[None]).max(2) + np.eye(len(objs))
        assert d.min() > 0.002


@pytest.mark.parametrize("obj_id", IDS)
def test_mesh_is_closed_oriented_and_labelled(obj_id):
    obj = get_object(obj_id)
    V, F, L = mesh(obj)
    assert V.shape == (obj.n_vertices, 3) and F.shape == (obj.n_triangles, 3)
    assert len(F) <= 5000  # rendered and collided: a few thousand triangles at most
    # closed two-manifold, consistently oriented: every directed edge once, with its reverse
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    key = e[:, 0] * len(V) + e[:, 1]
    assert len(np.unique(key)) == len(key), "a directed edge appears twice"
    assert np.isin(e[:, 1] * len(V) + e[:, 0], key).all(), "an edge has no opposite"
    assert np.isin(np.arange(len(V)), F).all(), "unused vertex"
    vol = mesh_volume(V, F)
    assert vol > 0, "faces point inwards"
    # library volume = mesh volume (closed bottles and cans: minus the air cavity)
    expected = vol - (obj.cavity_volume if obj.category in ("bottle", "can") else 0.0)
    assert obj.volume == pytest.approx(expected, rel=1e-3)  # 1e-3: the YAML keeps 9 decimals
    assert L.shape == (len(V),) and L.dtype == np.uint8 and L.max() < len(PART_LABELS)
    assert {PART_LABELS[k] for k in np.unique(L)} == set(obj.parts) == REQUIRED[obj.category]


@pytest.mark.slow
@pytest.mark.parametrize("obj_id", IDS)
def test_mesh_does_not_intersect_itself(obj_id):
    """Every triangle separates outside from inside: 50 µm off its centroid along its normal the
    winding number is 0, against it 1 (a self-intersecting or doubled surface gives 2 or -1)."""
    V, F, _ = mesh(obj_id)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1)
    big = area2 > 2e-7  # triangles over 0.1 mm²: the 50 µm step stays near their own surface
    n = n[big] / area2[big, None]
    cen = ((a + b + c) / 3)[big]
    w_out = np.concatenate([winding_number(V, F, q) for q in np.array_split(cen + 5e-5 * n, 40)])
    w_in = np.concatenate([winding_number(V, F, q) for q in np.array_split(cen - 5e-5 * n, 40)])
    assert np.abs(w_out).max() < 0.5 and np.abs(w_in - 1).max() < 0.5


@pytest.mark.parametrize("obj_id", IDS)
def test_part_labels_follow_the_ground_truth_rules(obj_id):
    obj = get_object(obj_id)
    V, _, L = mesh(obj)
    if obj.category in TOOLS:
        # the usable area is towards +x, the handle towards -x
        assert V[L == PART_LABELS.index("usable_area"), 0].mean() > V[
            L == PART_LABELS.index("handle"), 0].mean()
        return
    H = obj.dimensions["height"]
    z = V[:, 2]
    eps = 2e-6  # [m] vertex rounding (1 µm) and a ring placed on a boundary
    for part, lo, hi in (("bottom", -eps, H / 3 + eps), ("middle", H / 3 - eps, 2 * H / 3 + eps),
                         ("top", 2 * H / 3 - eps, H + eps)):
        zk = z[L == PART_LABELS.index(part)]
        assert zk.min() >= lo and zk.max() <= hi, part


@pytest.mark.parametrize("obj_id", IDS)
def test_mass_and_inertia_are_plausible(obj_id):
    obj = get_object(obj_id)
    lo, hi = MASS_RANGE[obj.category]
    assert lo <= obj.mass <= hi
    if not obj.part_materials:  # one material: its density, and mass = density × volume
        assert obj.density == pytest.approx(DENSITY[obj.material], rel=1e-3)
        assert obj.mass == pytest.approx(obj.density * obj.volume, rel=1e-3)
    else:  # a lighter (or heavier) handle moves the effective density off the main material's
        assert obj.density != pytest.approx(DENSITY.get(obj.material, 0.0), rel=1e-3)
    eig = np.linalg.eigvalsh(obj.inertia)
    assert eig.min() > 0
    assert eig.max() <= eig.sum() - eig.max() + 1e-12  # triangle inequality of principal moments
    V, _, _ = mesh(obj)
    assert np.all(np.array(obj.com) > V.min(0)) and np.all(np.array(obj.com) < V.max(0))
    if obj.category in TOOLS:
        assert obj.cavity_volume is None and obj.water_mass == 0.0
    else:  # "full": water of the cavity's volume; a real container holds at least half its own
        # weight in water (the heaviest, a steel or cast-iron pan, about 0.6)
        assert obj.is_container and obj.water_mass == pytest.approx(1000.0 * obj.cavity_volume)
        assert obj.water_mass > 0.5 * obj.mass
        # the water's centroid is on the axis, inside the body, above the base
        x, y, z = obj.cavity_centroid
        assert (x, y) == (0.0, 0.0)
        assert obj.dimensions.get("base", 0.0) < z < obj.dimensions["height"]


@pytest.mark.parametrize("obj_id", IDS)
def test_some_part_fits_the_gripper(obj_id):
    obj = get_object(obj_id)
    V, _, L = mesh(obj)
    th = np.linspace(0, np.pi, 180, endpoint=False)
    D = np.stack([np.cos(th), np.sin(th)], 1)
    widths = {}
    for part in obj.parts:
        proj = V[L == PART_LABELS.index(part), :2] @ D.T
        widths[part] = (proj.max(0) - proj.min(0)).min()  # fingers closing across the part
    if obj.category in OPEN:  # pinch the rim: one finger inside, one outside the wall
        top = V[L == PART_LABELS.index("top")]
        rho = np.hypot(top[:, 0], top[:, 1])
        assert rho.min() > FINGER_THICKNESS + CLEARANCE  # a finger fits inside the opening
        widths["top"] = min(widths["top"], rho.max() - rho.min())
    assert min(widths.values()) <= GRIPPER_OPENING - 2 * CLEARANCE, widths
    for part, w in obj.grasp_widths.items():  # the library's figures agree (or are tighter)
        assert w <= widths[part] + 1e-4  # 0.1 mm: the YAML keeps 4 decimals


@pytest.mark.parametrize("obj_id", IDS)
def test_resting_poses_put_the_object_on_the_table(obj_id):
    obj = get_object(obj_id)
    V, _, _ = mesh(obj)
    if obj.category in TOOLS:
        assert list(obj.poses) == ["sideways"]
        np.testing.assert_allclose(obj.poses["sideways"].X_TO, np.eye(4), atol=1e-12)
    else:
        assert "upright" in obj.poses and set(obj.poses) <= {"upright", "sideways", "upsidedown"}
    for pose, rest in obj.poses.items():
        X = rest.X_TO
        np.testing.assert_allclose(X[:3, :3] @ X[:3, :3].T, np.eye(3), atol=1e-12)
        p_T = V @ X[:3, :3].T + X[:3, 3]
        # 2 µm: xyz and rpy are stored to 6 decimals (1e-6 rad over 0.4 m is 0.4 µm)
        assert abs(p_T[:, 2].min()) < 2e-6, pose
        np.testing.assert_allclose(X[:2, 3], 0.0)
        z_O = X[:3, 2]  # the object's z axis in the table frame
        if pose == "upright" or obj.category in TOOLS:
            assert z_O[2] > np.cos(np.radians(35))
        elif pose == "upsidedown":
            assert z_O[2] < -np.cos(np.radians(35))
        else:
            assert abs(z_O[2]) < np.sin(np.radians(35))
        # the centre of mass projects inside the support polygon (vertices within 0.05 mm of
        # the table: the resting face, allowing for the 1 µm rounding)
        support = p_T[p_T[:, 2] < p_T[:, 2].min() + 5e-5, :2]
        com_T = X[:3, :3] @ np.array(obj.com) + X[:3, 3]
        hull = ConvexHull(support)
        assert (hull.equations[:, :2] @ com_T[:2] + hull.equations[:, 2]).max() < 0, pose


@pytest.mark.parametrize("obj_id", IDS[::4])
def test_sample_surface_is_uniform_with_outward_normals(obj_id):
    obj = get_object(obj_id)
    V, F, _ = mesh(obj)
    rng = np.random.default_rng(7)
    p, n, labels = sample_surface(obj, n=3000, rng=rng)
    assert p.shape == (3000, 3) and n.shape == (3000, 3) and labels.shape == (3000,)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-9)
    assert {PART_LABELS[k] for k in np.unique(labels)} == set(obj.parts)
    # points lie on the surface: inside the bounding box; normals point out: a step of 0.2 mm
    # (less than half the thinnest wall, 1 mm) along n leaves the solid, one against n enters.
    # 97 %: blade edges, tips and rims are thinner than 0.4 mm.
    assert np.all(p >= V.min(0) - 1e-9) and np.all(p <= V.max(0) + 1e-9)
    q = p[:150]
    w_out = winding_number(V, F, q + 2e-4 * n[:150])
    w_in = winding_number(V, F, q - 2e-4 * n[:150])
    assert np.mean(np.abs(w_out) < 0.5) > 0.97 and np.mean(w_in > 0.5) > 0.97
    # uniform by area: the share of points per part matches the share of area per part (by the
    # vertex-majority label of each triangle), within 4 sampling standard deviations
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    _, _, L = mesh(obj)
    tri_label = np.array([np.bincount(r, minlength=5).argmax() for r in L[F]])
    for k in np.unique(labels):
        share_area = a[tri_label == k].sum() / a.sum()
        share_pts = np.mean(labels == k)
        sd = np.sqrt(share_area * (1 - share_area) / len(labels))
        # + 0.03: labels come from the nearest vertex, the area share from the triangle majority
        assert abs(share_pts - share_area) < 4 * sd + 0.03, PART_LABELS[k]


def test_sample_surface_by_spacing_scales_with_size_and_is_reproducible():
    small, big = get_object("can_01"), get_object("pot_01")
    V, F, _ = mesh(small)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1).sum()
    p, _, _ = sample_surface(small, spacing=0.005, rng=np.random.default_rng(1))
    assert len(p) == round(area / 0.005 ** 2)
    q, _, _ = sample_surface(big, spacing=0.005, rng=np.random.default_rng(1))
    assert len(q) > 3 * len(p)
    p2, _, _ = sample_surface("can_01", spacing=0.005, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(p, p2)
    with pytest.raises(ValueError, match="exactly one of n and spacing"):
        sample_surface(small, n=10, spacing=0.01, rng=np.random.default_rng(0))


def test_unknown_object_and_unsuitable_pose_are_named():
    with pytest.raises(ScenarioError, match="unknown object 'mugg'; allowed: pan_01, pan_02"):
        get_object("mugg")
    with pytest.raises(ScenarioError, match="unknown pose 'lying'; allowed: upright, sideways"):
        get_object("cup_01").resting_pose("lying")
    with pytest.raises(ScenarioError, match="pose 'upsidedown' does not suit bottle_01.*upright"):
        get_object("bottle_01").resting_pose("upsidedown")


def test_files_are_addressed_through_the_package():
    obj = get_object("cup_01")
    assert obj.sdf_url == "package://tg_drake_models/objects/cup_01/cup_01.sdf"
    assert obj.mesh_url.endswith("objects/cup_01/cup_01.obj")
    for path in (obj.sdf_path, obj.mesh_path, obj.parts_path):
        assert path.is_file()
    assert '<mesh><uri>cup_01.obj</uri></mesh>' in obj.sdf_path.read_text()


def test_objects_command_lists_the_library(capsys):
    assert main(Namespace(json=True, category=None)) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["id"] for r in rows] == IDS
    assert rows[0].keys() >= {"id", "category", "extents", "mass", "parts"}
    assert main(Namespace(json=False, category="can")) == 0
    out = capsys.readouterr().out
    assert "can_01" in out and "cup_01" not in out and out.strip().endswith("4 objects")


def test_generator_reproduces_every_file_bit_for_bit():
    run = subprocess.run([sys.executable, str(REPO / "tools" / "make_objects.py"), "--check"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "every file matches" in run.stdout


def test_box_centre_is_half_the_height_above_the_base():
    """Library frames sit at the object's base: a bottle's centre is half its height up its axis
    (lying on its side, half a length away on the table, which targeting and placing allow for)."""
    from tg_drake.objects import box_centre, get_object

    for obj_id in ("bottle_02", "can_01", "cup_01", "hammer_01"):
        o = get_object(obj_id)
        c = box_centre(o)
        assert c[2] == pytest.approx(o.extents[2] / 2, abs=1e-4)  # extents: rounded
    assert np.linalg.norm(box_centre("bottle_02")[:2]) < 1e-3  # round: on its axis


def test_open_top_is_a_wide_opening_seen_unless_upside_down():
    from tg_drake.perception.ground_truth import interior_visible, open_top

    OPEN = {"cup", "glass", "bowl", "pot", "pan"}
    for obj_id, obj in load_library().items():
        if obj.is_tool:
            assert interior_visible(obj_id, "sideways") == 0.0
            continue
        assert interior_visible(obj_id, "upright") == float(obj.category in OPEN), obj_id
        assert interior_visible(obj_id, "upsidedown") == 0.0
    # A cylinder with a lid 4 mm down is closed; the same cylinder open at the top is not.
    g = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    wall = np.array([[0.03 * np.cos(a), 0.03 * np.sin(a), z] for a in g
                     for z in np.linspace(0, 0.12, 25)])
    disk = np.array([[r * np.cos(a), r * np.sin(a)] for a in g for r in np.linspace(0, 0.03, 8)])
    lid = np.column_stack([disk, np.full(len(disk), 0.116)])
    bottom = np.column_stack([disk, np.full(len(disk), 0.004)])
    labels = np.zeros(len(wall) + len(disk), int)
    assert not open_top(np.vstack([wall, lid]), labels)
    assert open_top(np.vstack([wall, bottom]), labels)
