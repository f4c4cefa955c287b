"""Writes the robot and table model files in models/ from the published figures.

    python -m tools.make_robot_models          # (re)write models/iiwa14, models/wsg_50,
                                               # models/table
    python -m tools.make_robot_models --check  # fail if the committed files differ from the output

The robots' figures (kinematics, limits; WSG 50 dimensions, stroke, force) are those of
tg_drake.robot, the one source of them; the links' masses, inertias and collision primitives
(cylinders, spheres, boxes) and the table are the model's own and live here. The WSG finger pads
and the table top carry compliant-hydroelastic properties; the settings are the ones measured to
hold a grasp on this kind of machine (see the station module's docstring).
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

from tg_drake.robot import (
    IIWA_FLANGE_Z,
    IIWA_JOINTS,
    WSG_BODY,
    WSG_BODY_CENTRE_G,
    WSG_BODY_MASS,
    WSG_BODY_SIZE,
    WSG_FINGER_JOINTS,
    WSG_FINGER_MASS,
    WSG_FINGER_VELOCITY,
    WSG_FINGERS,
    WSG_FORCE_LIMIT,
    WSG_PAD_CENTRE_Y,
    WSG_PAD_FRICTION,
    WSG_PAD_SIZE,
    WSG_STROKE,
)
from tg_drake.table import table_sdf

MODELS = Path(__file__).resolve().parents[1] / "models"

PI = math.pi

# link: (mass [kg], com xyz, (Ixx, Iyy, Izz), collision (radius, length, centre xyz, rpy) or
# sphere).
IIWA_LINKS = {
    "iiwa_link_0": (5.00, (-0.1, 0, 0.07), (0.05, 0.06, 0.03),
                    ("cylinder", 0.139, 0.17, (-0.015, 0, 0.07), (0, 0, 0))),
    "iiwa_link_1": (5.76, (0, -0.03, 0.12), (0.033, 0.0333, 0.0123),
                    ("cylinder", 0.101, 0.29, (0, -0.014, 0.14), (0, 0, 0))),
    "iiwa_link_2": (6.35, (0.0003, 0.059, 0.042), (0.0305, 0.011, 0.0304),
                    ("cylinder", 0.101, 0.29, (0, 0.056, 0.035), (PI / 2, 0, 0))),
    "iiwa_link_3": (3.50, (0, 0.03, 0.13), (0.025, 0.0238, 0.0076),
                    ("cylinder", 0.092, 0.29, (0, 0.025, 0.137), (0, 0, 0))),
    "iiwa_link_4": (3.50, (0, 0.067, 0.034), (0.017, 0.006, 0.0164),
                    ("cylinder", 0.092, 0.25, (0, 0.056, 0.025), (PI / 2, 0, 0))),
    "iiwa_link_5": (3.50, (0.0001, 0.021, 0.076), (0.01, 0.0087, 0.00449),
                    ("cylinder", 0.07, 0.29, (0, 0.03, 0.13), (-0.3, 0, 0))),
    "iiwa_link_6": (1.80, (0, 0.0006, 0.0004), (0.0049, 0.0047, 0.0036),
                    ("sphere", 0.07, None, (0, 0, 0), (0, 0, 0))),
    "iiwa_link_7": (1.20, (0, 0, 0.02), (0.001, 0.001, 0.001),
                    ("cylinder", 0.04, 0.045, (0, 0, 0.0225), (0, 0, 0))),
}

IIWA_COLOR = {"iiwa_link_0": "0.4 0.4 0.4 1", "iiwa_link_7": "0.4 0.4 0.4 1"}
IIWA_ORANGE = "1.0 0.42 0.04 1"

# The pads' hydroelastic modulus [Pa]. At 1e6 a thin part under a 40-80 N grip (a tool's
# handle, a container's wall) sank 3-5 mm into a 12 mm pad, most near its edges where the
# pressure field is shallow: tools slipped at the lift and objects stayed stuck to a pad as it
# opened. 1e7 (a stiff rubber) kept them out (docs/design.md, "Simulation settings").
PAD_HYDRO = dict(modulus=1e7, resolution=0.005, dissipation=3.0, mu=WSG_PAD_FRICTION)

# The table's facts and model are tg_drake.table's (the station sizes it from the scenario).


def _f(v) -> str:
    return " ".join(f"{x:.6g}" for x in v)


def _inertial_urdf(mass, com, inertia) -> str:
    ixx, iyy, izz = inertia
    return (f'    <inertial>\n      <origin xyz="{_f(com)}" rpy="0 0 0"/>\n'
            f'      <mass value="{mass}"/>\n'
            f'      <inertia ixx="{ixx:.6g}" ixy="0" ixz="0" iyy="{iyy:.6g}" iyz="0" '
            f'izz="{izz:.6g}"/>\n'
            f'    </inertial>\n')


def _geometry_urdf(shape) -> str:
    kind, radius, length = shape[0], shape[1], shape[2]
    if kind == "sphere":
        return f'<sphere radius="{radius}"/>'
    return f'<cylinder radius="{radius}" length="{length}"/>'


def _box_urdf(visual: str, collision: str, xyz, size, material: str, properties: str = "") -> str:
    """A link's box as a visual and a collision element of the same origin and size."""
    origin = f'      <origin xyz="{_f(xyz)}" rpy="0 0 0"/>\n'
    box = f'      <geometry><box size="{_f(size)}"/></geometry>\n'
    return (f'    <visual name="{visual}">\n' + origin + box
            + f'      <material name="{material}"/>\n    </visual>\n'
            f'    <collision name="{collision}">\n' + origin + box + properties
            + "    </collision>")


def _transmission_urdf(joint: str, actuator: str, interface: str) -> str:
    """The transmission that makes Drake give `joint` an actuator named `actuator`."""
    return (f'  <transmission name="{joint}_transmission">\n'
            "    <type>transmission_interface/SimpleTransmission</type>\n"
            f'    <joint name="{joint}"><hardwareInterface>{interface}'
            "</hardwareInterface></joint>\n"
            f'    <actuator name="{actuator}"><mechanicalReduction>1</mechanicalReduction>'
            "</actuator>\n  </transmission>")


def iiwa_urdf() -> str:
    out = ['<?xml version="1.0"?>',
           "<!-- KUKA LBR iiwa 14 R820, written by tools/make_robot_models.py from",
           "     the figures of tg_drake/robot.py (KUKA's data sheet): 7 revolute joints about",
           "     their local z axes, primitive collision cylinders. Do not edit by hand. -->",
           '<robot name="iiwa14" xmlns:drake="http://drake.mit.edu">',
           '  <material name="iiwa_orange"><color rgba="' + IIWA_ORANGE + '"/></material>',
           '  <material name="iiwa_grey"><color rgba="0.4 0.4 0.4 1"/></material>']
    for link, (mass, com, inertia, shape) in IIWA_LINKS.items():
        _, _, _, centre, rpy = shape
        material = "iiwa_grey" if link in IIWA_COLOR else "iiwa_orange"
        geometry = _geometry_urdf(shape)
        out.append(f'  <link name="{link}">')
        out.append(_inertial_urdf(mass, com, inertia).rstrip("\n"))
        out.append(f'    <visual>\n      <origin xyz="{_f(centre)}" rpy="{_f(rpy)}"/>\n'
                   f'      <geometry>{geometry}</geometry>\n'
                   f'      <material name="{material}"/>\n    </visual>')
        out.append(f'    <collision name="{link}_collision">\n'
                   f'      <origin xyz="{_f(centre)}" rpy="{_f(rpy)}"/>\n'
                   f'      <geometry>{geometry}</geometry>\n    </collision>')
        out.append("  </link>")
    # The tool flange: a frame IIWA_FLANGE_Z above link 7 (a massless link on a fixed joint).
    out.append('  <link name="iiwa_link_ee"/>')
    for name, parent, child, xyz, rpy, limit, velocity, effort in IIWA_JOINTS:
        out.append(f'  <joint name="{name}" type="revolute">\n'
                   f'    <parent link="{parent}"/>\n    <child link="{child}"/>\n'
                   f'    <origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/>\n    <axis xyz="0 0 1"/>\n'
                   f'    <limit lower="{-limit}" upper="{limit}" effort="{effort}" '
                   f'velocity="{velocity}"/>\n'
                   f'    <dynamics damping="0.0"/>\n  </joint>')
        out.append(_transmission_urdf(name, f"{name}_actuator", "PositionJointInterface"))
    out.append('  <joint name="iiwa_joint_ee" type="fixed">\n'
               '    <parent link="iiwa_link_7"/>\n    <child link="iiwa_link_ee"/>\n'
               f'    <origin xyz="0 0 {IIWA_FLANGE_Z}" rpy="0 0 0"/>\n  </joint>')
    # The coarse collision cylinders of links two apart overlap in normal postures; the real arm's
    # links do not collide there, so those pairs are filtered (groups of three consecutive links).
    links = list(IIWA_LINKS)
    for i in range(len(links) - 2):
        group = f"iiwa_links_{i}_{i + 2}"
        members = "".join(f'<drake:member link="{link}"/>' for link in links[i:i + 3])
        out.append(f'  <drake:collision_filter_group name="{group}">{members}'
                   f'<drake:ignored_collision_filter_group name="{group}"/>'
                   "</drake:collision_filter_group>")
    out.append("</robot>")
    return "\n".join(out) + "\n"


def _box_inertia(mass, size):
    x, y, z = size
    return (mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12)


def _compliant_urdf(h) -> str:
    """A compliant-hydroelastic collision's properties (Drake's URDF form: values as
    attributes)."""
    return ("      <drake:proximity_properties>\n"
            "        <drake:compliant_hydroelastic/>\n"
            f'        <drake:hydroelastic_modulus value="{h["modulus"]:.6g}"/>\n'
            f'        <drake:mesh_resolution_hint value="{h["resolution"]}"/>\n'
            f'        <drake:hunt_crossley_dissipation value="{h["dissipation"]}"/>\n'
            f'        <drake:mu_dynamic value="{h["mu"]}"/>\n'
            f'        <drake:mu_static value="{h["mu"]}"/>\n'
            "      </drake:proximity_properties>\n")


def wsg_urdf() -> str:
    """The WSG 50 in URDF: Drake parses a URDF file in well under a millisecond, the same model
    as an SDFormat file in about 26 ms (libsdformat's file loading), and the planner builds an
    arm plant with the gripper many times per plan."""
    out = ['<?xml version="1.0"?>',
           "<!-- Schunk WSG 50 parallel gripper, written by tools/make_robot_models.py from",
           "     the figures of tg_drake/robot.py (the WSG 50 data sheet). Frame of `body` (G):",
           "     fingers close along ±x, the approach direction is +y, the grasp point is",
           f"     {WSG_PAD_CENTRE_Y} m along +y. Finger pads are plain boxes with",
           "     compliant-hydroelastic properties. The two prismatic finger joints are the "
           "model's only",
           "     actuated joints (pydrake's SchunkWsgPositionController expects exactly that).",
           "     Do not edit by hand. -->",
           '<robot name="wsg_50" xmlns:drake="http://drake.mit.edu">',
           '  <material name="wsg_body"><color rgba="0.7 0.7 0.75 1"/></material>',
           '  <material name="wsg_pad"><color rgba="0.2 0.2 0.2 1"/></material>',
           f'  <link name="{WSG_BODY}">',
           _inertial_urdf(WSG_BODY_MASS, WSG_BODY_CENTRE_G,
                          _box_inertia(WSG_BODY_MASS, WSG_BODY_SIZE)).rstrip("\n"),
           _box_urdf("body_visual", "body_collision", WSG_BODY_CENTRE_G, WSG_BODY_SIZE,
                     "wsg_body"),
           "  </link>"]
    for finger, joint, sign, lower, upper in zip(WSG_FINGERS, WSG_FINGER_JOINTS, (-1, 1),
                                                 (-WSG_STROKE, 0.0), (0.0, WSG_STROKE),
                                                 strict=False):
        # The finger frame moves with its joint; the pad's inner face sits at x = q (the joint
        # value), so the opening is q_right − q_left.
        pad_xyz = (sign * WSG_PAD_SIZE[0] / 2, WSG_PAD_CENTRE_Y, 0.0)
        out += [f'  <link name="{finger}">',
                _inertial_urdf(WSG_FINGER_MASS, pad_xyz,
                               _box_inertia(WSG_FINGER_MASS, WSG_PAD_SIZE)).rstrip("\n"),
                _box_urdf(f"{finger}_visual", f"{finger}_pad", pad_xyz, WSG_PAD_SIZE, "wsg_pad",
                          _compliant_urdf(PAD_HYDRO)),
                "  </link>",
                f'  <joint name="{joint}" type="prismatic">\n'
                f'    <parent link="{WSG_BODY}"/>\n    <child link="{finger}"/>\n'
                '    <origin xyz="0 0 0" rpy="0 0 0"/>\n    <axis xyz="1 0 0"/>\n'
                f'    <limit lower="{lower}" upper="{upper}" effort="{WSG_FORCE_LIMIT}" '
                f'velocity="{WSG_FINGER_VELOCITY}"/>\n'
                '    <dynamics damping="0"/>\n  </joint>',
                _transmission_urdf(joint, joint, "EffortJointInterface")]
    out.append("</robot>")
    return "\n".join(out) + "\n"


FILES = {
    "iiwa14/iiwa14.urdf": iiwa_urdf,
    "wsg_50/wsg_50.urdf": wsg_urdf,
    "table/table.sdf": table_sdf,
}


def write(root: Path) -> list[Path]:
    written = []
    for rel, make in FILES.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(make())
        written.append(path)
    return written


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="regenerate into a temporary folder and compare with models/")
    args = parser.parse_args(argv)
    if not args.check:
        for path in write(MODELS):
            print(f"wrote {path.relative_to(MODELS.parent)}")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        differ = [rel for rel in FILES
                  if (Path(tmp) / rel).read_bytes() != (MODELS / rel).read_bytes()
                  ] if write(Path(tmp)) else []
    for rel in differ:
        print(f"differs from the generator: models/{rel}", file=sys.stderr)
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
