"""What physically happened to the target object: grasped, lifted, placed — read off port values.

These checks take what the plant's output ports give (``contact_results``: a `ContactResults`;
``body_poses``: world poses; ``wsg.state``: the finger positions) and the geometry ids of the
bodies involved (`HandGeometries`, read once from the finalized plant's model). They are the
ground truth of an execution, never inputs to the pipeline's perception or reasoning.

The one rule for "held" is `is_held`: both finger pads touch the object and the fingers stand more
than `CLOSED_ON_AIR` apart.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# The closed-on-air tolerance of every "held" check in tg_drake (the run's outcomes, the training
# episodes' labels, the scripted grasp): a finger opening (distance between the pads' inner
# faces) at or below this means the fingers closed on air, whatever touches their outsides [m].
# Pads that close on nothing stop at 0 (each finger's joint limit; measured −0.03 mm in a grasp
# episode); 1 mm is well above that and under the thinnest walls the library's objects offer the
# pads (a pot's rim, 1–1.5 mm; a bowl's 4–5 mm wall leaves the squeezing pads about 4 mm apart).
CLOSED_ON_AIR = 0.001
# Placement tolerances: distance of the object's centre from the place target on the table [m],
# tilt of its axis from the pose it was picked in [rad].
PLACE_XY_TOLERANCE = 0.05
PLACE_TILT_TOLERANCE = np.deg2rad(20)


def is_held(touches_left: bool, touches_right: bool, opening: float) -> bool:
    """The one rule for "the gripper holds the object": both pads touch it and the fingers are
    more than `CLOSED_ON_AIR` apart (`opening` [m], between the pads' inner faces)."""
    return bool(touches_left and touches_right and opening > CLOSED_ON_AIR)


@dataclass(frozen=True)
class HandGeometries:
    """Collision geometry ids of the target object, the two WSG fingers and the table."""

    object: frozenset
    left: frozenset
    right: frozenset
    table: frozenset

    @classmethod
    def from_plant(cls, plant, *, object_body, wsg_instance, table_instance) -> HandGeometries:
        """Reads the ids from a finalized plant's model (no context needed)."""
        def of(body):
            return frozenset(plant.GetCollisionGeometriesForBody(body))
        table = frozenset(g for b in plant.GetBodyIndices(table_instance)
                          for g in plant.GetCollisionGeometriesForBody(plant.get_body(b)))
        return cls(object=of(object_body),
                   left=of(plant.GetBodyByName("left_finger", wsg_instance)),
                   right=of(plant.GetBodyByName("right_finger", wsg_instance)), table=table)


@dataclass
class HandContact:
    opening: float  # [m] distance between the finger pads' inner faces
    left: bool  # the left pad touches the object
    right: bool  # the right pad touches the object
    hydroelastic: int  # hydroelastic contact surfaces on the object

    @property
    def held(self) -> bool:
        return is_held(self.left, self.right, self.opening)


def contact_pairs(contact_results) -> list[tuple]:
    """(GeometryId, GeometryId) of every hydroelastic surface and point pair in `contact_results`
    (the plant's ``contact_results`` output)."""
    pairs = []
    for i in range(contact_results.num_hydroelastic_contacts()):
        s = contact_results.hydroelastic_contact_info(i).contact_surface()
        pairs.append((s.id_M(), s.id_N()))
    for i in range(contact_results.num_point_pair_contacts()):
        info = contact_results.point_pair_contact_info(i).point_pair()
        pairs.append((info.id_A, info.id_B))
    return pairs


def hand_contact(contact_results, *, wsg_q, geometries: HandGeometries) -> HandContact:
    """Which finger pads touch the object; `wsg_q` = (q_left, q_right) [m], the first two entries
    of the station's ``wsg.state``."""
    touches_left = touches_right = False
    obj = geometries.object
    surfaces = sum(1 for i in range(contact_results.num_hydroelastic_contacts())
                   if {contact_results.hydroelastic_contact_info(i).contact_surface().id_M(),
                       contact_results.hydroelastic_contact_info(i).contact_surface().id_N()}
                   & obj)
    for a, b in contact_pairs(contact_results):
        other = b if a in obj else a if b in obj else None
        if other is None:
            continue
        touches_left |= other in geometries.left
        touches_right |= other in geometries.right
    return HandContact(float(wsg_q[1] - wsg_q[0]), touches_left, touches_right, surfaces)


def touches_table(contact_results, *, geometries: HandGeometries) -> bool:
    """Does the object touch the table (any hydroelastic surface or point pair)?"""
    obj, table = geometries.object, geometries.table
    return any((a in obj and b in table) or (b in obj and a in table)
               for a, b in contact_pairs(contact_results))


def placed(X_WO_picked, X_WO_now, p_W_target_xy, *, released: bool,
           p_OC=(0.0, 0.0, 0.0)) -> tuple[bool, str]:
    """Is the object standing at the place target, in the pose it was picked in, and let go
    (resting on the table with the gripper open)?

    The place target is where the planner puts the centre of the object's box (what perception
    sees), so the distance is measured from the true box centre `p_OC` (in the object frame O; a
    library object's frame origin sits at its base, half a length away from the centre when it
    lies on its side)."""
    p_WC = X_WO_now.multiply(np.asarray(p_OC, float))
    xy_error = float(np.linalg.norm(p_WC[:2] - np.asarray(p_W_target_xy)))
    z_before = X_WO_picked.rotation().col(2)
    z_now = X_WO_now.rotation().col(2)
    tilt = float(np.arccos(np.clip(np.dot(z_before, z_now), -1.0, 1.0)))
    if not released:
        return False, "not let go: still held, or not resting on the table"
    if xy_error > PLACE_XY_TOLERANCE:
        return False, f"{xy_error * 100:.1f} cm from the place target"
    if tilt > PLACE_TILT_TOLERANCE:
        return False, f"tipped over ({np.rad2deg(tilt):.0f}° from its picked pose)"
    return True, f"{xy_error * 100:.1f} cm from the target, tilted {np.rad2deg(tilt):.0f}°"
