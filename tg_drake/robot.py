"""The KUKA LBR iiwa 14 R820 and the Schunk WSG 50 gripper: the one source of their facts.

Every figure of the two robots that tg_drake uses lives here, with its unit and where it comes
from: tools/make_robot_models.py writes models/iiwa14 and models/wsg_50 from these numbers (a test
parses the models and compares them with this module), and the scenario's mount and home posture,
the pre-grasps, the DGI closing volume, the planner's checks and the pictures read them.

Plain numbers and numpy only (no Drake), so that every core may import it.

Frames:
- the iiwa's joints turn about their local z axes; link 7's frame is the last joint's child, the
  tool flange 0.045 m further along its z axis;
- G, the WSG body frame (link `body` of models/wsg_50): the fingers close along ±x_G, the gripper
  approaches along +y_G, z_G is across the finger pads. A finger's joint value is the x_G of its
  pad's inner face, so the opening (distance between the inner faces) is q_right − q_left.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

# --- KUKA LBR iiwa 14 R820 (KUKA's data sheet and the published kinematic figures) --------------


class IiwaJoint(NamedTuple):
    name: str
    parent: str  # parent link
    child: str  # child link
    xyz: tuple  # origin of the child in the parent link's frame [m]
    rpy: tuple  # roll, pitch, yaw of the child in the parent link's frame [rad]
    limit: float  # position limit, symmetric: −limit … +limit [rad]
    velocity: float  # maximum speed [rad/s]
    effort: float  # maximum torque [N·m]


_PI = math.pi
IIWA_JOINTS = (
    IiwaJoint("iiwa_joint_1", "iiwa_link_0", "iiwa_link_1", (0, 0, 0.1575), (0, 0, 0),
              2.96706, 1.48353, 320),
    IiwaJoint("iiwa_joint_2", "iiwa_link_1", "iiwa_link_2", (0, 0, 0.2025), (_PI / 2, 0, _PI),
              2.09440, 1.48353, 320),
    IiwaJoint("iiwa_joint_3", "iiwa_link_2", "iiwa_link_3", (0, 0.2045, 0), (_PI / 2, 0, _PI),
              2.96706, 1.74533, 176),
    IiwaJoint("iiwa_joint_4", "iiwa_link_3", "iiwa_link_4", (0, 0, 0.2155), (_PI / 2, 0, 0),
              2.09440, 1.30900, 176),
    IiwaJoint("iiwa_joint_5", "iiwa_link_4", "iiwa_link_5", (0, 0.1845, 0), (-_PI / 2, _PI, 0),
              2.96706, 2.26893, 110),
    IiwaJoint("iiwa_joint_6", "iiwa_link_5", "iiwa_link_6", (0, 0, 0.2155), (_PI / 2, 0, 0),
              2.09440, 2.35619, 40),
    IiwaJoint("iiwa_joint_7", "iiwa_link_6", "iiwa_link_7", (0, 0.081, 0), (-_PI / 2, _PI, 0),
              3.05433, 2.35619, 40),
)
IIWA_JOINT_NAMES = tuple(j.name for j in IIWA_JOINTS)
IIWA_POSITION_LIMITS = np.array([j.limit for j in IIWA_JOINTS])  # ± [rad], joints 1–7
IIWA_VELOCITY_LIMITS = np.array([j.velocity for j in IIWA_JOINTS])  # [rad/s], joints 1–7
IIWA_POSITION_LIMITS.flags.writeable = IIWA_VELOCITY_LIMITS.flags.writeable = False
IIWA_FLANGE_Z = 0.045  # [m] the tool flange along link 7's z axis from link 7's frame.

# Our home posture: it keeps the arm clear of the camera's view of the table [rad], joints 1–7.
IIWA_HOME = (0.0, -0.6, 0.0, -1.9, 0.0, 1.0, 0.0)

# --- Schunk WSG 50 (Schunk's data sheet), in the gripper frame G --------------------------------

WSG_BODY_SIZE = (0.146, 0.0725, 0.05)  # [m] the housing box along x_G, y_G, z_G.
# [m] the housing box's centre in G, where the model puts it: the box spans y_G ∈ [−0.0575, 0.015],
# the pads start at its front.
WSG_BODY_CENTRE_G = (0.0, -0.0213, 0.0)
WSG_BODY_MASS = 0.99  # [kg] the housing.
WSG_FINGER_MASS = 0.05  # [kg] each finger.
WSG_PAD_SIZE = (0.012, 0.082, 0.02)  # [m] a finger pad (with its tip): thickness along x_G, length
# along the approach y_G, width along z_G.
WSG_PAD_CENTRE_Y = 0.055  # [m] y_G of the pads' centres (the data sheet's grasp point, about
# 0.055 m from the body origin along the fingers): the pads span y_G ∈ [0.014, 0.096].
WSG_PALM_Y = WSG_PAD_CENTRE_Y - WSG_PAD_SIZE[1] / 2  # [m] 0.014: where the pads start.
WSG_FINGERTIP_Y = WSG_PAD_CENTRE_Y + WSG_PAD_SIZE[1] / 2  # [m] 0.096: the pads' tips.
# [m] the grasp point, between the pads' centres, in G: where the object should sit in the hand
# (the data sheet: the object within the last 0.04–0.06 m of the fingers).
WSG_GRASP_POINT_G = np.array([0.0, WSG_PAD_CENTRE_Y, 0.0])
WSG_GRASP_POINT_G.flags.writeable = False
WSG_STROKE = 0.055  # [m] each finger travels 0 … 0.055 m from the centre.
WSG_MAX_OPENING = 2 * WSG_STROKE  # [m] 0.110: the pads' inner faces fully open.
WSG_FORCE_LIMIT = 80.0  # [N] per finger: the drive's limit.
WSG_PAD_FRICTION = 1.0  # Coulomb μ (static and dynamic) of the finger pads' contact material.
WSG_FINGER_VELOCITY = 0.42  # [m/s] finger speed (the data sheet: up to 420 mm/s).
WSG_BODY = "body"  # the link whose frame is G
WSG_FINGERS = ("left_finger", "right_finger")  # finger links, closing from −x_G and +x_G
WSG_FINGER_JOINTS = ("left_finger_sliding_joint", "right_finger_sliding_joint")  # prismatic
# along x_G: the left from −WSG_STROKE (open) to 0, the right from 0 to +WSG_STROKE. They are the
# model's only actuated joints (pydrake's SchunkWsgPositionController expects exactly that).
WSG_OPEN_POSITIONS = (-WSG_STROKE, WSG_STROKE)  # [m] the finger joints fully open.

# --- The WSG on the iiwa -------------------------------------------------------------------------

# The mount: G's origin 0.114 m out along link 7's z axis, the approach +y_G along that axis.
# The data sheet's figure is the body's centre about 0.114 m out along the flange's z axis; the
# station measures it from link 7's frame (the flange is IIWA_FLANGE_Z further out), which puts the
# housing's back face 0.0115 m past the flange. Roll, pitch, yaw [rad] and translation [m] of G in
# link 7's frame.
X_7G_RPY = (np.pi / 2, 0.0, np.pi / 2)
X_7G_XYZ = (0.0, 0.0, 0.114)


def _rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """R = Rz(yaw) · Ry(pitch) · Rx(roll) (the roll-pitch-yaw convention of SDF, URDF and Drake)."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


X_7G = np.eye(4)  # the mount as a 4 × 4 homogeneous transform of G in link 7's frame
X_7G[:3, :3] = _rpy_matrix(*X_7G_RPY)
X_7G[:3, 3] = X_7G_XYZ
X_7G.flags.writeable = False


# --- The arm's reach -----------------------------------------------------------------------------
# Joint 4 alone sets the distance from the shoulder (joints 1–2) to the wrist centre (link 6's
# origin, where the axes of joints 5–7 meet): the wrist centre lies in a spherical shell about the
# shoulder, whatever the other joints. A gripper pose whose wrist centre is outside that shell has
# no inverse kinematics: a necessary condition, not a sufficient one.
_SHOULDER_Z = IIWA_JOINTS[0].xyz[2] + IIWA_JOINTS[1].xyz[2]  # [m] above the base
_UPPER_ARM = abs(IIWA_JOINTS[2].xyz[1]) + abs(IIWA_JOINTS[3].xyz[2])  # [m] joint 2 → joint 4
_FOREARM = abs(IIWA_JOINTS[4].xyz[1]) + abs(IIWA_JOINTS[5].xyz[2])  # [m] joint 4 → joint 6
WRIST_SHELL = (  # [m] the shortest (joint 4 at its limit) and longest (straight) wrist distance
    math.sqrt(_UPPER_ARM ** 2 + _FOREARM ** 2
              - 2 * _UPPER_ARM * _FOREARM * math.cos(math.pi - IIWA_JOINTS[3].limit)),
    _UPPER_ARM + _FOREARM)
WRIST_OFFSET_G = abs(IIWA_JOINTS[6].xyz[1]) + X_7G_XYZ[2]  # [m] the wrist centre back along −y_G
# from G (link 7's axis is y_G)


def wrist_reach_margin(X_BG: np.ndarray) -> float:
    """[m] how far inside the iiwa's reachable shell (`WRIST_SHELL`) the wrist centre of gripper
    pose X_BG (in the iiwa's base frame: link 0, joint 1 along its z) lies: negative when no
    joint configuration within joint 4's range puts the gripper there, whatever the other joints
    (a necessary condition of the inverse kinematics, not a sufficient one)."""
    X = np.asarray(X_BG, float)
    wrist = X[:3, 3] - WRIST_OFFSET_G * X[:3, 1]
    d = float(np.linalg.norm(wrist - np.array([0.0, 0.0, _SHOULDER_Z])))
    return min(d - WRIST_SHELL[0], WRIST_SHELL[1] - d)


def wsg_pad_boxes(opening: float = WSG_MAX_OPENING) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """The two finger pads in G at the given opening [m] (distance between their inner faces):
    ((centre, full size), (centre, full size)) for the left (−x_G) and the right (+x_G) pad."""
    return tuple((np.array([s * (opening / 2 + WSG_PAD_SIZE[0] / 2), WSG_PAD_CENTRE_Y, 0.0]),
                  np.array(WSG_PAD_SIZE)) for s in (-1.0, 1.0))
