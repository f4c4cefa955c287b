"""The feasibility stage's geometric refusals (tg_drake.grasping.pads): what lies between the open
pads of a grasp pose, measured on perceived points, against FeasibilityConfig's limits; and the
stage applying them (`assess_candidates`) so that the planner never sees a refused pose."""

from __future__ import annotations

import numpy as np
import pytest
from grasp_helpers import box_object, grasp_pose, ranked

from tg_drake.grasping.expansion import ExpansionConfig, retreat_above_table
from tg_drake.grasping.feasibility import FeasibilityConfig, assess_candidates
from tg_drake.grasping.pads import (
    DOES_NOT_FIT,
    WOULD_NOT_HOLD,
    closes_along_length,
    contact_share,
    depth_between_pads,
    extent_along_closing,
    geometric_refusal,
    open_pad_cover,
    overlap_across_pads,
    pad_area_below_middle,
    part_width,
    torsion_lever,
    width_between_pads,
)
from tg_drake.planning.planner import plan_pick_and_place
from tg_drake.types import SceneDescription

TABLE_CLEARANCE = ExpansionConfig().table_clearance  # [m] the scored poses' pads above the table


def clear_of_table(X_WG, table_z):
    """X_WG moved back above the table by the rule of the scored poses
    (tg_drake.grasping.expansion), clearing it by TABLE_CLEARANCE."""
    moved, ok = retreat_above_table(X_WG, table_z, approach_distance=0.0,
                                    config=ExpansionConfig(max_retreat=np.inf))
    return moved[0] if ok[0] else None


def test_a_part_wider_than_the_opening_does_not_fit():
    config = FeasibilityConfig()
    wide = box_object([0.75, 0.1, 0.06], [0.07, 0.16, 0.12])
    X = grasp_pose([0.75, 0.1, 0.09], [0, 0, -1], [0, 1, 0])
    assert part_width(wide, "top", X) == pytest.approx(0.16)
    assert part_width(wide, "top", X) > config.opening - config.width_margin
    reason = geometric_refusal(wide, "top", X, None, config)
    assert reason.startswith(DOES_NOT_FIT) and "0.160 m across the fingers" in reason


def pan_with_handle():
    """A pan-like object: its points (and centroid) around (0.7, 0, 0.03), a handle out to 0.96 m
    along x."""
    pan = box_object([0.9, 0.0, 0.03], [0.12, 0.03, 0.03], parts=("handle",))
    t = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    r = np.linspace(0.0, 0.12, 8)
    body = np.array([[0.7 + ri * np.cos(a), ri * np.sin(a), 0.03] for ri in r for a in t])
    handle = np.array([[x, y, 0.03] for x in np.linspace(0.84, 0.96, 13)
                       for y in np.linspace(-0.01, 0.01, 5)])
    pan.p_W = np.vstack([body, np.tile(body[-60:], (4, 1)), handle])  # centroid near the middle
    pan.visible = np.ones(len(pan.p_W), bool)
    return pan


def test_the_stage_refuses_a_grasp_too_far_from_the_weight_and_tells_the_part_would_not_hold():
    """A handle grasp 0.2 m out from the pan's centroid, the fingers closing along y: the weight
    turns it about the closing axis with a 0.2 m lever, which the pads resist by friction alone.
    The stage refuses it (score 0, its reason), tells the logic that no grasp on the handle would
    hold, and the planner does not try it but passes the reason on."""
    pan = pan_with_handle()
    config = FeasibilityConfig()
    far = grasp_pose([0.9, 0.0, 0.03], approach_W=[0, 0, -1], closing_W=[0, 1, 0])
    centroid = pan.p_W.mean(axis=0)
    assert torsion_lever(far, centroid) == pytest.approx(0.9 - centroid[0], abs=1e-9)
    assert torsion_lever(far, centroid) > config.max_torsion_lever
    X_WT = np.eye(4)
    X_WT[2, 3] = -0.1  # the table well below: this test is about the lever alone
    out = assess_candidates(SceneDescription(objects=[pan], X_WT=X_WT), ranked([(far, "handle")]),
                            category=None, approach=0.1, config=config)
    assert out.score[0] == 0.0
    assert out.feasibility_reasons[0].startswith(WOULD_NOT_HOLD)
    assert "m lever (at most 0.12 m)" in out.feasibility_reasons[0]
    assert out.unholdable_parts == ("handle",)
    result = plan_pick_and_place(out, target=pan, place_xy=[0.5, -0.3], table_z=-0.1)
    assert result.status == "unreachable"
    assert result.candidate_reasons[0] == out.feasibility_reasons[0]
    # Nearer the weight (0.11 m from the centroid) the lever is short enough.
    near = grasp_pose([0.83, 0.0, 0.03], approach_W=[0, 0, -1], closing_W=[0, 1, 0])
    assert torsion_lever(near, centroid) < config.max_torsion_lever
    assert "lever" not in geometric_refusal(pan, "handle", near, centroid, config)


def test_a_rim_grasp_needs_only_the_wall_between_the_fingers():
    """A bowl is wider than the WSG opens, so its top's box rules every grasp out; measured on the
    perceived points between the pads, a grasp across the wall fits."""
    angle = np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False)
    height = np.linspace(0.0, 0.06, 25)
    ring = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    # Outer wall radius 0.08 m and inner 0.076 m, 6 cm high, centred at (0.75, 0.1) on the table.
    p_W = np.concatenate([np.column_stack([0.75 + r * ring[:, 0], 0.1 + r * ring[:, 1],
                                           np.full(len(ring), z)])
                          for r in (0.08, 0.076) for z in height])
    bowl = box_object([0.75, 0.1, 0.03], [0.16, 0.16, 0.06])
    bowl.p_W = p_W
    rim = grasp_pose([0.75 + 0.078, 0.1, 0.055], approach_W=[0, 0, -1], closing_W=[1, 0, 0])
    assert part_width(bowl, "top", rim) == pytest.approx(0.16)
    # The inner wall's farthest point under the 2 cm wide pads: 1 cm along the wall, where the
    # ring has curved away from the grasp point.
    inner = 0.078 - np.sqrt(0.076 ** 2 - 0.01 ** 2)
    assert width_between_pads(bowl, rim) == pytest.approx(2 * inner, abs=5e-4)
    # Across the middle of the bowl the fingers would land on both walls: no fit, and nothing
    # between the pads at all far from the bowl.
    across = grasp_pose([0.75, 0.1, 0.055], approach_W=[0, 0, -1], closing_W=[1, 0, 0])
    assert width_between_pads(bowl, across) > FeasibilityConfig().opening
    away = grasp_pose([0.5, -0.2, 0.055], approach_W=[0, 0, -1], closing_W=[1, 0, 0])
    assert width_between_pads(bowl, away) == np.inf


def test_fingers_do_not_close_along_a_long_part():
    knife = box_object([0.75, 0.0, 0.01], [0.02, 0.09, 0.02], parts=("handle",))
    along = grasp_pose([0.75, 0.0, 0.01], approach_W=[0, 0, -1], closing_W=[0, 1, 0])
    across = grasp_pose([0.75, 0.0, 0.01], approach_W=[0, 0, -1], closing_W=[1, 0, 0])
    assert "along the 0.090 m length of handle" in closes_along_length(
        knife, "handle", along, FeasibilityConfig())
    assert closes_along_length(knife, "handle", across, FeasibilityConfig()) == ""
    cube = box_object([0.75, 0.0, 0.03], [0.06, 0.06, 0.06], parts=("middle",))
    assert closes_along_length(cube, "middle", along, FeasibilityConfig()) == ""


def test_a_part_too_flat_for_the_pads_above_the_table_is_refused():
    def plate(thickness):
        g = np.linspace(-0.03, 0.03, 31)
        x, y, z = np.meshgrid(g, g, np.linspace(0.0, thickness, 4))
        o = box_object([0.75, 0.0, thickness / 2], [0.06, 0.06, thickness], parts=("middle",))
        o.p_W = np.column_stack([0.75 + x.ravel(), y.ravel(), z.ravel()])
        return o

    OPEN = FeasibilityConfig().opening
    X = clear_of_table(grasp_pose([0.75, 0.0, 0.0], approach_W=[0, 0, -1],
                                  closing_W=[0, 1, 0]), 0.0)
    # The pads' tips stay TABLE_CLEARANCE above the table: a plate reaches (thickness −
    # clearance) between them.
    for thickness in (0.012, 0.03):
        assert depth_between_pads(plate(thickness), X, OPEN) == pytest.approx(
            thickness - TABLE_CLEARANCE, abs=1e-9)
    assert depth_between_pads(plate(0.01), X, OPEN) < FeasibilityConfig().min_pad_depth
    assert depth_between_pads(plate(0.012), X, OPEN) > FeasibilityConfig().min_pad_depth
    # Completion mirrored a 6 mm blade up to 18 mm: the points the camera saw decide.
    blade = plate(0.018)
    blade.visible = blade.p_W[:, 2] <= 0.006 + 1e-9
    assert depth_between_pads(blade, X, OPEN) == pytest.approx(0.006 - TABLE_CLEARANCE, abs=1e-9)
    # Seen points near the grasp but none between the pads (a blade lying below the pads' tips,
    # completion mirrored upwards): nothing the camera saw reaches between them.
    low = plate(0.018)
    low.visible = low.p_W[:, 2] <= 0.002 + 1e-9
    assert depth_between_pads(low, X, OPEN) == 0.0


def test_a_thin_edge_pinched_in_a_side_grasp_is_refused():
    def blade(height, z0=0.02):
        # A vertical plate 6 cm long, 2 mm thick, `height` tall, its bottom at z0.
        g = np.linspace(-0.03, 0.03, 31)
        x, y, z = np.meshgrid(g, np.linspace(-0.001, 0.001, 3), np.linspace(0, height, 61))
        o = box_object([0.75, 0.0, z0 + height / 2], [0.06, 0.002, height], parts=("middle",))
        o.p_W = np.column_stack([0.75 + x.ravel(), y.ravel(), z0 + z.ravel()])
        return o

    config = FeasibilityConfig()
    # A side grasp closing across the plate's thickness, the pads' 20 mm width vertical.
    X = grasp_pose([0.75, 0.0, 0.03], approach_W=[1, 0, 0], closing_W=[0, 1, 0])
    assert overlap_across_pads(blade(0.03, 0.015), X, config.opening) == pytest.approx(
        0.02, abs=1e-3)  # the plate covers the pads' whole width
    edge = blade(0.002, 0.029)
    assert overlap_across_pads(edge, X, config.opening) == pytest.approx(0.002, abs=1e-9)
    assert "thin edge" in geometric_refusal(edge, "middle", X, None, config)
    assert geometric_refusal(blade(0.03, 0.015), "middle", X, None, config) == ""


def test_a_tool_pressed_only_above_its_widest_section_is_refused():
    # A handle lying on the table along x: 10 cm long, 20 mm wide, 16 mm tall (knife_03's as
    # perceived), its top and its sides down to 4 mm seen.
    g = np.linspace(0.70, 0.80, 51)
    top = np.stack(np.meshgrid(g, np.linspace(-0.01, 0.01, 11), [0.016]), -1).reshape(-1, 3)
    sides = np.stack(np.meshgrid(g, [-0.01, 0.01], np.linspace(0.004, 0.016, 7)), -1).reshape(-1, 3)
    handle = box_object([0.75, 0.0, 0.008], [0.10, 0.02, 0.016], parts=("handle",))
    handle.p_W = np.concatenate([top, sides])
    handle.visible = np.ones(len(handle.p_W), bool)
    handle.is_tool = True
    config = FeasibilityConfig()
    OPEN = config.opening
    # Straight down across it, the pads' tips 4 mm above the table: their faces cover its lower
    # half (4 to 8 mm) over their 20 mm width.
    down = clear_of_table(grasp_pose([0.75, 0.0, 0.0], approach_W=[0, 0, -1],
                                     closing_W=[0, 1, 0]), 0.0)
    assert pad_area_below_middle(handle, down, OPEN, 0.0) == pytest.approx(80e-6, rel=0.05)
    assert geometric_refusal(handle, "handle", down, None, config) == ""
    # End-on along it, the approach tilted 35° down to clear the table: only the corner at the
    # pads' tips reaches below its middle (a triangle of about 4² / (2 sin 35° cos 35°) mm²).
    s, c = np.sin(np.deg2rad(35.0)), np.cos(np.deg2rad(35.0))
    end_on = clear_of_table(grasp_pose([0.73, 0.0, 0.008], approach_W=[c, 0, -s],
                                       closing_W=[0, 1, 0]), 0.0)
    assert pad_area_below_middle(handle, end_on, OPEN, 0.0) == pytest.approx(17e-6, rel=0.15)
    assert "lower half" in geometric_refusal(handle, "handle", end_on, None, config)
    # The rule is the tools': a container's wall or handle is not rounded about a middle height
    # (the other checks pass this grasp).
    handle.is_tool = False
    assert geometric_refusal(handle, "handle", end_on, None, config) == ""


def test_torsion_lever_is_the_weight_arm_about_the_closing_axis():
    # Top-down across a handle along world x (fingers closing along y): a weight 0.1 m further
    # along the handle turns the object about the closing axis with a 0.1 m lever.
    X = grasp_pose([0.7, 0.0, 0.02], approach_W=[0, 0, -1], closing_W=[0, 1, 0])
    assert torsion_lever(X, [0.8, 0.0, 0.02]) == pytest.approx(0.1, abs=1e-12)
    # A weight along the closing axis (a rim grasp: the pan's middle beyond the wall), or
    # straight below, presses on the pads' faces instead: no lever about the closing axis.
    assert torsion_lever(X, [0.7, 0.1, 0.02]) == pytest.approx(0.0, abs=1e-12)
    assert torsion_lever(X, [0.7, 0.0, -0.1]) == pytest.approx(0.0, abs=1e-12)


def test_an_object_past_both_pads_is_refused_one_past_a_single_pad_is_not():
    config = FeasibilityConfig()
    half = (config.opening - config.release_gap) / 2
    X = grasp_pose([0.7, 0.0, 0.03], approach_W=[0, 0, -1], closing_W=[1, 0, 0])
    # A can lying along x, 113 mm long, taken at its middle with the fingers along its axis.
    can = box_object([0.7, 0.0, 0.03], [0.113, 0.055, 0.055], parts=("middle",))
    t = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    xs = np.linspace(-0.0565, 0.0565, 30)
    can.p_W = np.array([[0.7 + x, 0.0275 * np.cos(a), 0.03 + 0.0275 * np.sin(a)]
                        for x in xs for a in t])
    lo, hi = extent_along_closing(can, X, config.release_band)
    assert (lo, hi) == pytest.approx((-0.0565, 0.0565), abs=1e-9)
    assert -lo > half and hi > half
    # A shorter one, 102 mm (can_03 as perceived), its middle part a 34 mm band that fits the
    # opening: 4 mm a side at the release kept it wedged in simulation.
    short = box_object([0.7, 0.0, 0.03], [0.034, 0.055, 0.055], parts=("middle",))
    short.p_W = np.array([[0.7 + x, 0.0275 * np.cos(a), 0.03 + 0.0275 * np.sin(a)]
                          for x in np.linspace(-0.051, 0.051, 27) for a in t])
    assert "could not let go" in geometric_refusal(short, "middle", X, None, config)
    # Held in the air by another gripper (a pass's receiver taking it), nothing is let go here.
    assert "could not let go" not in geometric_refusal(short, "middle", X, None, config,
                                                       held=True)
    # A cup's handle reaching past one pad only: the fingers open clear of the other side.
    cup = box_object([0.7, 0.0, 0.03], [0.105, 0.075, 0.06], parts=("middle",))
    cup.p_W = can.p_W[np.abs(can.p_W[:, 0] - 0.7) <= 0.0375] + [0.0, 0.0, 0.0]
    cup.p_W = np.vstack([cup.p_W, [[0.7 + 0.0675, 0.0, 0.03]]])  # the handle's far end
    lo, hi = extent_along_closing(cup, X, config.release_band)
    assert hi > half and not -lo > half
    # A lying cup taken across its body, 46 mm on the near side and its handle out to 73 mm
    # on the far one (cup_04 as perceived): let go in simulation.
    body = np.array([[0.7 + x, 0.0275 * np.cos(a), 0.03 + 0.0275 * np.sin(a)]
                     for x in np.linspace(-0.046, 0.046, 24) for a in t])
    cup.p_W = np.vstack([body, [[0.7 + x, 0.0, 0.03] for x in np.linspace(0.046, 0.073, 8)]])
    lo, hi = extent_along_closing(cup, X, config.release_band)
    assert -lo < half < hi


def test_a_step_under_the_pads_is_refused():
    config = FeasibilityConfig()
    # A top-down grasp closing along y over a horizontal 6 mm rod along x (the pads' width),
    # 20 mm above the table; with a 20 mm wide block where one pad edge lands, a step.
    X = grasp_pose([0.75, 0.0, 0.02], approach_W=[0, 0, -1], closing_W=[0, 1, 0])

    def rod(block: bool):
        g = np.linspace(-0.03, 0.03, 61)
        a = np.linspace(0, 2 * np.pi, 24, endpoint=False)
        x, t = np.meshgrid(g, a)
        p = np.column_stack([0.75 + x.ravel(), 0.003 * np.cos(t.ravel()),
                             0.02 + 0.003 * np.sin(t.ravel())])
        if block:  # x from 0.75 − 0.012 back: y ±10 mm
            b = np.linspace(-0.01, 0.01, 21)
            bx, by, bz = np.meshgrid(np.linspace(0.72, 0.742, 12), b, np.linspace(0.01, 0.03, 11))
            p = np.vstack([p, np.column_stack([bx.ravel(), by.ravel(), bz.ravel()])])
        o = box_object([0.75, 0.0, 0.02], [0.06, 0.006, 0.006], parts=("middle",))
        o.p_W = p
        return o

    assert contact_share(rod(False), X, config.opening) == 1.0
    # A handle running past one pad in one band (a cup's): the pad goes beside it there.
    handled = rod(False)
    h = np.linspace(0.0, 0.06, 31)
    handled.p_W = np.vstack([handled.p_W, np.column_stack([np.full(31, 0.758), h,
                                                           np.full(31, 0.02)])])
    assert contact_share(handled, X, config.opening) == 1.0
    stepped = rod(True)
    assert contact_share(stepped, X, config.opening) == pytest.approx(0.25)
    assert "step or taper" in geometric_refusal(stepped, "middle", X, None, config)
    assert geometric_refusal(rod(False), "middle", X, None, config) == ""


def test_a_thin_tool_shaft_is_refused():
    def bar(width):
        # A tool's bar along x on the table, `width` across, 16 mm tall, its top and sides seen.
        g = np.linspace(0.70, 0.80, 51)
        top = np.stack(np.meshgrid(g, np.linspace(-width / 2, width / 2, 5), [0.016]),
                       -1).reshape(-1, 3)
        sides = np.stack(np.meshgrid(g, [-width / 2, width / 2], np.linspace(0.0, 0.016, 9)),
                         -1).reshape(-1, 3)
        o = box_object([0.75, 0.0, 0.008], [0.10, width, 0.016], parts=("handle",))
        o.p_W = np.concatenate([top, sides])
        o.visible = np.ones(len(o.p_W), bool)
        o.is_tool = True
        return o

    config = FeasibilityConfig()
    down = clear_of_table(grasp_pose([0.75, 0.0, 0.0], approach_W=[0, 0, -1],
                                     closing_W=[0, 1, 0]), 0.0)
    assert "thin shaft" in geometric_refusal(bar(0.006), "handle", down, None, config)
    assert geometric_refusal(bar(0.012), "handle", down, None, config) == ""


def test_an_open_pad_coming_down_on_the_object_is_refused():
    config = FeasibilityConfig()
    # A top-down grasp closing along y over a 30 mm block (a hammer's head); a 25 mm bar (its
    # handle) runs from it along y under where the right pad comes down (y 55 to 67 mm).
    X = grasp_pose([0.75, 0.0, 0.02], approach_W=[0, 0, -1], closing_W=[0, 1, 0])
    g = np.linspace(-0.015, 0.015, 16)
    head = np.stack(np.meshgrid(g, g, [0.035]), -1).reshape(-1, 3) + [0.75, 0.0, 0.0]
    bar = np.stack(np.meshgrid(np.linspace(-0.0125, 0.0125, 7), np.linspace(0.015, 0.1, 44),
                               [0.025]), -1).reshape(-1, 3) + [0.75, 0.0, 0.0]
    o = box_object([0.75, 0.0, 0.0175], [0.03, 0.03, 0.035], parts=("usable_area",))
    o.p_W = head
    assert open_pad_cover(o, X, config.opening) == 0.0
    o.p_W = np.vstack([head, bar])
    assert open_pad_cover(o, X, config.opening) > config.max_pad_cover
    o.is_tool = True
    assert "come down on the object" in geometric_refusal(o, "usable_area", X, None, config)
    # A container's wall or handle under a pad yields (a cup's handle did, and the grasp held):
    # the check is for tools lying on the table only.
    o.is_tool = False
    assert "come down on the object" not in geometric_refusal(o, "usable_area", X, None, config)


