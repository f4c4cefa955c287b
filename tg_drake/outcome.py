"""What physically happened to the target object: grasped, lifted, placed — read off the plant.

These checks read the simulated state (poses, finger positions, hydroelastic contact surfaces); they
are the ground truth of an execution, never inputs to the pipeline's decisions.
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


@dataclass
class HandContact:
    opening: float  # [m] distance between the finger pads' inner faces
    left: bool  # the left pad touches the object
    right: bool  # the right pad touches the object
    hydroelastic: int  # hydroelastic contact surfaces on the object

    @property
    def held(self) -> bool:
        return self.left and self.right and self.opening > CLOSED_ON_AIR


def hand_contact(plant, plant_context, *, object_body, wsg_instance) -> HandContact:
    """Which finger pads touch the object, from the plant's contact results."""
    q = plant.GetPositions(plant_context, wsg_instance)
    results = plant.get_contact_results_output_port().Eval(plant_context)
    object_geometries = set(plant.GetCollisionGeometriesForBody(object_body))
    left = set(plant.GetCollisionGeometriesForBody(
        plant.GetBodyByName("left_finger", wsg_instance)))
    right = set(plant.GetCollisionGeometriesForBody(
        plant.GetBodyByName("right_finger", wsg_instance)))
    touches_left = touches_right = False
    surfaces = 0
    pairs = []
    for i in range(results.num_hydroelastic_contacts()):
        s = results.hydroelastic_contact_info(i).contact_surface()
        pairs.append((s.id_M(), s.id_N()))
        if s.id_M() in object_geometries or s.id_N() in object_geometries:
            surfaces += 1
    for i in range(results.num_point_pair_contacts()):
        info = results.point_pair_contact_info(i).point_pair()
        pairs.append((info.id_A, info.id_B))
    for a, b in pairs:
        other = b if a in object_geometries else a if b in object_geometries else None
        if other is None:
            continue
        touches_left |= other in left
        touches_right |= other in right
    return HandContact(float(q[1] - q[0]), touches_left, touches_right, surfaces)


def touches_table(plant, plant_context, *, object_body, table_instance) -> bool:
    """Does the object touch the table top (any hydroelastic surface or point pair)?"""
    results = plant.get_contact_results_output_port().Eval(plant_context)
    obj = set(plant.GetCollisionGeometriesForBody(object_body))
    table = {g for b in plant.GetBodyIndices(table_instance)
             for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))}
    pairs = [(results.hydroelastic_contact_info(i).contact_surface().id_M(),
              results.hydroelastic_contact_info(i).contact_surface().id_N())
             for i in range(results.num_hydroelastic_contacts())]
    pairs += [(results.point_pair_contact_info(i).point_pair().id_A,
               results.point_pair_contact_info(i).point_pair().id_B)
              for i in range(results.num_point_pair_contacts())]
    return any((a in obj and b in table) or (b in obj and a in table) for a, b in pairs)


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
