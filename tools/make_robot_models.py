"""Writes the robot and table model files in models/ from the published figures.

    python -m tools.make_robot_models          # (re)write models/iiwa14, models/wsg_50, models/table
    python -m tools.make_robot_models --check  # fail if the committed files differ from the output

The figures (kinematics, limits, masses, inertias, collision cylinders; WSG 50 dimensions and
stroke) are those of ../shared/robot_facts.md. Collision geometry is primitive (cylinders, spheres,
boxes). The WSG finger pads and the table top carry compliant-hydroelastic properties; the settings
are the ones measured to hold a grasp on this kind of machine (see robot_facts.md and the station
module's docstring).
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

from tg_drake.table import table_sdf

MODELS = Path(__file__).resolve().parents[1] / "models"

PI = math.pi

# KUKA LBR iiwa 14 R820. joint: (parent, child, xyz, rpy, limit [rad], velocity [rad/s], effort [N·m]).
IIWA_JOINTS = [
    ("iiwa_joint_1", "iiwa_link_0", "iiwa_link_1", (0, 0, 0.1575), (0, 0, 0), 2.96706, 1.48353, 320),
    ("iiwa_joint_2", "iiwa_link_1", "iiwa_link_2", (0, 0, 0.2025), (PI / 2, 0, PI), 2.09440, 1.48353,
     320),
    ("iiwa_joint_3", "iiwa_link_2", "iiwa_link_3", (0, 0.2045, 0), (PI / 2, 0, PI), 2.96706, 1.74533,
     176),
    ("iiwa_joint_4", "iiwa_link_3", "iiwa_link_4", (0, 0, 0.2155), (PI / 2, 0, 0), 2.09440, 1.30900,
     176),
    ("iiwa_joint_5", "iiwa_link_4", "iiwa_link_5", (0, 0.1845, 0), (-PI / 2, PI, 0), 2.96706, 2.26893,
     110),
    ("iiwa_joint_6", "iiwa_link_5", "iiwa_link_6", (0, 0, 0.2155), (PI / 2, 0, 0), 2.09440, 2.35619,
     40),
    ("iiwa_joint_7", "iiwa_link_6", "iiwa_link_7", (0, 0.081, 0), (-PI / 2, PI, 0), 3.05433, 2.35619,
     40),
]

# link: (mass [kg], com xyz, (Ixx, Iyy, Izz), collision (radius, length, centre xyz, rpy) or sphere).
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

# Schunk WSG 50 (robot_facts.md). Body frame G: fingers close along ±x, approach along +y.
WSG_BODY_SIZE = (0.146, 0.0725, 0.05)  # x × y × z [m]
WSG_BODY_MASS = 0.99  # [kg]
WSG_BODY_CENTRE_Y = -0.0213  # body box spans y ∈ [-0.0575, 0.015]; fingers start at its front.
WSG_FINGER_MASS = 0.05  # [kg]
WSG_PAD_SIZE = (0.012, 0.082, 0.02)  # x (thickness) × y (length, along approach) × z [m]
WSG_PAD_CENTRE_Y = 0.055  # pad spans y ∈ [0.014, 0.096]: grasp point 0.055 m from the body origin.
WSG_STROKE = 0.055  # each finger 0 … 0.055 m from the centre: full opening 0.110 m.
WSG_FORCE = 80.0  # [N] drive limit per finger.
WSG_VELOCITY = 0.42  # [m/s] finger speed (WSG 50 data sheet: up to 420 mm/s).
PAD_HYDRO = dict(modulus=1e6, resolution=0.005, dissipation=3.0, mu=1.0)

# The table's facts and model are tg_drake.table's (the station sizes it from the scenario).


def _f(v) -> str:
    return " ".join(f"{x:.6g}" for x in v)


def _inertial_urdf(mass, com, inertia) -> str:
    ixx, iyy, izz = inertia
    return (f'    <inertial>\n      <origin xyz="{_f(com)}" rpy="0 0 0"/>\n'
            f'      <mass value="{mass}"/>\n'
            f'      <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/>\n'
            f'    </inertial>\n')


def _geometry_urdf(shape) -> str:
    kind, radius, length = shape[0], shape[1], shape[2]
    if kind == "sphere":
        return f'<sphere radius="{radius}"/>'
    return f'<cylinder radius="{radius}" length="{length}"/>'


def iiwa_urdf() -> str:
    out = ['<?xml version="1.0"?>',
           "<!-- KUKA LBR iiwa 14 R820, written by tools/make_robot_models.py from",
           "     ../shared/robot_facts.md: 7 revolute joints about their local z axes, primitive",
           "     collision cylinders. Do not edit by hand. -->",
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
    # The tool flange: a frame 0.045 m above link 7 (a massless link on a fixed joint).
    out.append('  <link name="iiwa_link_ee"/>')
    for name, parent, child, xyz, rpy, limit, velocity, effort in IIWA_JOINTS:
        out.append(f'  <joint name="{name}" type="revolute">\n'
                   f'    <parent link="{parent}"/>\n    <child link="{child}"/>\n'
                   f'    <origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/>\n    <axis xyz="0 0 1"/>\n'
                   f'    <limit lower="{-limit}" upper="{limit}" effort="{effort}" '
                   f'velocity="{velocity}"/>\n'
                   f'    <dynamics damping="0.0"/>\n  </joint>')
        out.append(f'  <transmission name="{name}_transmission">\n'
                   '    <type>transmission_interface/SimpleTransmission</type>\n'
                   f'    <joint name="{name}"><hardwareInterface>PositionJointInterface'
                   '</hardwareInterface></joint>\n'
                   f'    <actuator name="{name}_actuator"><mechanicalReduction>1</mechanicalReduction>'
                   '</actuator>\n  </transmission>')
    out.append('  <joint name="iiwa_joint_ee" type="fixed">\n'
               '    <parent link="iiwa_link_7"/>\n    <child link="iiwa_link_ee"/>\n'
               '    <origin xyz="0 0 0.045" rpy="0 0 0"/>\n  </joint>')
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


def _sdf_inertial(mass, size, pose="0 0 0 0 0 0") -> str:
    ixx, iyy, izz = _box_inertia(mass, size)
    return (f"      <inertial>\n        <pose>{pose}</pose>\n        <mass>{mass}</mass>\n"
            f"        <inertia><ixx>{ixx:.6g}</ixx><ixy>0</ixy><ixz>0</ixz><iyy>{iyy:.6g}</iyy>"
            f"<iyz>0</iyz><izz>{izz:.6g}</izz></inertia>\n      </inertial>\n")


def _compliant(h) -> str:
    return ("          <drake:proximity_properties>\n"
            "            <drake:compliant_hydroelastic/>\n"
            f"            <drake:hydroelastic_modulus>{h['modulus']:.6g}</drake:hydroelastic_modulus>\n"
            f"            <drake:mesh_resolution_hint>{h['resolution']}</drake:mesh_resolution_hint>\n"
            f"            <drake:hunt_crossley_dissipation>{h['dissipation']}"
            "</drake:hunt_crossley_dissipation>\n"
            f"            <drake:mu_dynamic>{h['mu']}</drake:mu_dynamic>\n"
            f"            <drake:mu_static>{h['mu']}</drake:mu_static>\n"
            "          </drake:proximity_properties>\n")


def wsg_sdf() -> str:
    bx, by, bz = WSG_BODY_SIZE
    px, py, pz = WSG_PAD_SIZE
    fingers = []
    for side, sign, lower, upper in (("left", -1, -WSG_STROKE, 0.0), ("right", 1, 0.0, WSG_STROKE)):
        # The finger frame moves with its joint; the pad's inner face sits at x = q (the joint value),
        # so the opening is q_right − q_left.
        pad_pose = f"{sign * px / 2:.6g} {WSG_PAD_CENTRE_Y} 0 0 0 0"
        fingers.append(
            f'    <link name="{side}_finger">\n'
            + _sdf_inertial(WSG_FINGER_MASS, WSG_PAD_SIZE, pad_pose)
            + f'      <visual name="{side}_finger_visual">\n        <pose>{pad_pose}</pose>\n'
            f"        <geometry><box><size>{px} {py} {pz}</size></box></geometry>\n"
            "        <material><diffuse>0.2 0.2 0.2 1</diffuse></material>\n      </visual>\n"
            f'      <collision name="{side}_finger_pad">\n        <pose>{pad_pose}</pose>\n'
            f"        <geometry><box><size>{px} {py} {pz}</size></box></geometry>\n"
            + _compliant(PAD_HYDRO)
            + "      </collision>\n    </link>\n"
            f'    <joint name="{side}_finger_sliding_joint" type="prismatic">\n'
            f"      <parent>body</parent>\n      <child>{side}_finger</child>\n"
            "      <axis>\n        <xyz>1 0 0</xyz>\n"
            f"        <limit><lower>{lower}</lower><upper>{upper}</upper>"
            f"<effort>{WSG_FORCE}</effort><velocity>{WSG_VELOCITY}</velocity></limit>\n"
            "        <dynamics><damping>0</damping></dynamics>\n      </axis>\n    </joint>\n")
    body_pose = f"0 {WSG_BODY_CENTRE_Y} 0 0 0 0"
    return (
        '<?xml version="1.0"?>\n'
        "<!-- Schunk WSG 50 parallel gripper, written by tools/make_robot_models.py from\n"
        "     ../shared/robot_facts.md. Frame of `body` (G): fingers close along ±x, the approach\n"
        "     direction is +y, the grasp point is 0.055 m along +y. Finger pads are plain boxes with\n"
        "     compliant-hydroelastic properties. The two prismatic finger joints are the model's only\n"
        "     actuated joints (pydrake's SchunkWsgPositionController expects exactly that).\n"
        "     Do not edit by hand. -->\n"
        '<sdf version="1.9" xmlns:drake="http://drake.mit.edu">\n'
        '  <model name="wsg_50">\n'
        '    <link name="body">\n'
        + _sdf_inertial(WSG_BODY_MASS, WSG_BODY_SIZE, body_pose)
        + '      <visual name="body_visual">\n'
        f"        <pose>{body_pose}</pose>\n"
        f"        <geometry><box><size>{bx} {by} {bz}</size></box></geometry>\n"
        "        <material><diffuse>0.7 0.7 0.75 1</diffuse></material>\n      </visual>\n"
        '      <collision name="body_collision">\n'
        f"        <pose>{body_pose}</pose>\n"
        f"        <geometry><box><size>{bx} {by} {bz}</size></box></geometry>\n"
        "      </collision>\n    </link>\n"
        + "".join(fingers)
        + "  </model>\n</sdf>\n")


FILES = {
    "iiwa14/iiwa14.urdf": iiwa_urdf,
    "wsg_50/wsg_50.sdf": wsg_sdf,
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
