"""What physically happened to the target object: grasped, lifted, placed — read off port values.

These checks take what the plant's output ports give (``contact_results``: a `ContactResults`;
``body_poses``: world poses; ``wsg.state``: the finger positions) and the geometry ids of the
bodies involved (`HandGeometries`, read once from the finalized plant's model). They are the
ground truth of an execution, never inputs to the pipeline's perception or reasoning.

The one rule for "held" is `is_held`: the object pushes each finger pad outwards, away from the
other, with at least `MIN_SQUEEZE` — it is squeezed between the pads' inner faces. The contact
forces say so whatever the object's thickness: a 1.5 mm knife blade squeezed by the compliant pads
(which sink into it ~1.4 mm) leaves the fingers under a millimetre apart and is held, while fingers
closed on air with the object pressing on their outsides feel a push inwards.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# [N] the least push of the object on each pad, outwards along the closing axis, for "squeezed
# between the pads" (every "held" check in tg_drake: the run's outcomes, the receiver's hold, the
# training episodes' labels, the scripted grasp). A closing WSG presses with its force limit (tens
# of newtons, `tg_drake.robot.WSG_FORCE_LIMIT`); an object that only grazes a pad's edge or rests
# on its end face pushes it sideways by a few millinewtons of solver noise along the axis. 1 N is
# far from both.
MIN_SQUEEZE = 1.0
# [m] fingers at or below this opening (between the pads' inner faces) have closed fully: said
# in reasons, not used for "held" (pads that close on nothing stop at 0, each finger's limit).
CLOSED_ON_AIR = 0.001
# Placement tolerances: distance of the object's centre from the place target on the table [m],
# change of its axis' angle to the table from the pose it was picked in [rad].
PLACE_XY_TOLERANCE = 0.05
PLACE_TILT_TOLERANCE = np.deg2rad(20)


def is_held(squeeze_left: float, squeeze_right: float) -> bool:
    """The one rule for "the gripper holds the object": it pushes each pad outwards (away from
    the other pad, along the closing axis) with at least `MIN_SQUEEZE` [N]."""
    return bool(squeeze_left >= MIN_SQUEEZE and squeeze_right >= MIN_SQUEEZE)


@dataclass(frozen=True)
class HandGeometries:
    """Collision geometry ids of the target object, the two WSG fingers and the table, and the
    index of the WSG's body (its frame's x axis is the closing axis: the right finger opens
    along +x, the left along −x)."""

    object: frozenset
    left: frozenset
    right: frozenset
    table: frozenset
    gripper: int  # the WSG body's index (in ``body_poses``)

    @classmethod
    def from_plant(cls, plant, *, object_body, wsg_instance, table_instance) -> HandGeometries:
        """Reads the ids from a finalized plant's model (no context needed)."""
        def of(body):
            return frozenset(plant.GetCollisionGeometriesForBody(body))
        table = frozenset(g for b in plant.GetBodyIndices(table_instance)
                          for g in plant.GetCollisionGeometriesForBody(plant.get_body(b)))
        return cls(object=of(object_body),
                   left=of(plant.GetBodyByName("left_finger", wsg_instance)),
                   right=of(plant.GetBodyByName("right_finger", wsg_instance)), table=table,
                   gripper=int(plant.GetBodyByName("body", wsg_instance).index()))


@dataclass
class HandContact:
    opening: float  # [m] distance between the finger pads' inner faces
    left: bool  # the left pad touches the object
    right: bool  # the right pad touches the object
    hydroelastic: int  # hydroelastic contact surfaces on the object
    squeeze_left: float = 0.0  # [N] the object's push on the left pad, outwards (along −x_G)
    squeeze_right: float = 0.0  # [N] the object's push on the right pad, outwards (along +x_G)

    @property
    def held(self) -> bool:
        return is_held(self.squeeze_left, self.squeeze_right)

    def describe(self) -> str:
        """The pads' state in words, for a reason: which pads touch, how hard the object pushes
        them apart, how far apart the fingers stand."""
        return (f"left pad {'touching' if self.left else 'free'}, right pad "
                f"{'touching' if self.right else 'free'}, pushed apart "
                f"{self.squeeze_left:.1f} N / {self.squeeze_right:.1f} N (held from "
                f"{MIN_SQUEEZE:.0f} N each), fingers {self.opening * 1000:.1f} mm apart")


@dataclass(frozen=True)
class Contact:
    """One hydroelastic surface or point pair of the plant's ``contact_results``: its two
    geometries, the contact force on `a`'s body [N] and a point of it [m] (world frame), and
    whether it is a hydroelastic surface."""

    a: object  # GeometryId
    b: object  # GeometryId
    f_a: np.ndarray
    p: np.ndarray
    hydroelastic: bool


def contacts_of(contact_results) -> list[Contact]:
    """Every contact in `contact_results`. Drake gives a hydroelastic surface's force on the body
    of its geometry M (``F_Ac_W``, at the surface's centroid) and a point pair's on the body of
    its geometry B (``contact_force``, at ``contact_point``): `a` is M, or A."""
    out = []
    for i in range(contact_results.num_hydroelastic_contacts()):
        info = contact_results.hydroelastic_contact_info(i)
        s = info.contact_surface()
        out.append(Contact(s.id_M(), s.id_N(), np.asarray(info.F_Ac_W().translational(), float),
                           np.asarray(s.centroid(), float), True))
    for i in range(contact_results.num_point_pair_contacts()):
        info = contact_results.point_pair_contact_info(i)
        pair = info.point_pair()
        out.append(Contact(pair.id_A, pair.id_B, -np.asarray(info.contact_force(), float),
                           np.asarray(info.contact_point(), float), False))
    return out


def contact_pairs(contact_results) -> list[tuple]:
    """(GeometryId, GeometryId) of every hydroelastic surface and point pair in `contact_results`
    (the plant's ``contact_results`` output)."""
    return [(c.a, c.b) for c in contacts_of(contact_results)]


def forces_on(contacts: list[Contact], *, on: frozenset, by: frozenset) -> list[np.ndarray]:
    """The contact forces [N] (world frame) on the geometries `on` from the geometries `by`, one
    per contact between them (`contacts`: `contacts_of`)."""
    return ([c.f_a for c in contacts if c.a in on and c.b in by]
            + [-c.f_a for c in contacts if c.b in on and c.a in by])


def contact_points(contacts: list[Contact], *, a: frozenset, b: frozenset) -> list[np.ndarray]:
    """World points [m] where geometries `a` touch geometries `b` (`contacts`: `contacts_of`):
    each hydroelastic surface's centroid, each point pair's contact point."""
    return [c.p for c in contacts if {c.a, c.b} & a and {c.a, c.b} & b]


def part_touched(points_W, X_WO, vertices_O, labels) -> int | None:
    """The part label most of `points_W` lie nearest to: each point taken into the object's
    frame (X_WO, 4×4) and given the label of the nearest of the object's labelled mesh vertices
    (`vertices_O` (V, 3), `labels` (V,)); None without points or labels."""
    if not len(points_W) or vertices_O is None or not len(vertices_O):
        return None
    X = np.asarray(X_WO, float)
    p_O = (np.asarray(points_W, float) - X[:3, 3]) @ X[:3, :3]
    V = np.asarray(vertices_O, float)
    nearest = np.argmin(((p_O[:, None, :] - V[None, :, :]) ** 2).sum(axis=2), axis=1)
    values, counts = np.unique(np.asarray(labels)[nearest], return_counts=True)
    return int(values[np.argmax(counts)])


def hand_contact(contact_results, *, wsg_q, geometries: HandGeometries, R_WG) -> HandContact:
    """Which finger pads touch the object and how hard it pushes each outwards; `wsg_q` =
    (q_left, q_right) [m], the first two entries of the station's ``wsg.state``; `R_WG`: the
    orientation of the WSG's body in the world (a RotationMatrix; its x axis is the closing
    axis)."""
    x_G = np.asarray(R_WG.col(0), float).ravel()
    obj = geometries.object
    contacts = contacts_of(contact_results)
    left = forces_on(contacts, on=geometries.left, by=obj)
    right = forces_on(contacts, on=geometries.right, by=obj)
    return HandContact(float(wsg_q[1] - wsg_q[0]), bool(left), bool(right),
                       sum(1 for c in contacts if c.hydroelastic and {c.a, c.b} & obj),
                       squeeze_left=float(-sum(f @ x_G for f in left)),
                       squeeze_right=float(sum(f @ x_G for f in right)))


def touches_table(contact_results, *, geometries: HandGeometries) -> bool:
    """Does the object touch the table (any hydroelastic surface or point pair)?"""
    obj, table = geometries.object, geometries.table
    return any((a in obj and b in table) or (b in obj and a in table)
               for a, b in contact_pairs(contact_results))


def axis_elevation(X_WO) -> float:
    """The angle of the object's axis z_O above the table plane [rad]: π/2 upright, 0 lying,
    −π/2 upside down, whichever way it faces about the vertical."""
    return float(np.arcsin(np.clip(X_WO.rotation().col(2)[2], -1.0, 1.0)))


def placed(X_WO_picked, X_WO_now, p_W_target_xy, *, released: bool,
           p_OC=(0.0, 0.0, 0.0)) -> tuple[bool, str]:
    """Is the object resting at the place target, in the pose it was picked in, and let go
    (resting on the table with the gripper open)?

    The place target is where the planner puts the centre of the object's box (what perception
    sees), so the distance is measured from the true box centre `p_OC` (in the object frame O; a
    library object's frame origin sits at its base, half a length away from the centre when it
    lies on its side). The pose is the axis' angle to the table (`axis_elevation`): tipping
    changes it, a turn about the vertical does not — the planner may turn the object about the
    vertical to place it (`PlannerConfig.place_yaws`), and a lying object turned so still lies."""
    p_WC = X_WO_now.multiply(np.asarray(p_OC, float))
    xy_error = float(np.linalg.norm(p_WC[:2] - np.asarray(p_W_target_xy)))
    tilt = abs(axis_elevation(X_WO_now) - axis_elevation(X_WO_picked))
    if not released:
        return False, "not let go: still held, or not resting on the table"
    if xy_error > PLACE_XY_TOLERANCE:
        return False, f"{xy_error * 100:.1f} cm from the place target"
    if tilt > PLACE_TILT_TOLERANCE:
        return False, (f"tipped over (its axis {np.rad2deg(tilt):.0f}° off its picked pose's "
                       "angle to the table)")
    return True, f"{xy_error * 100:.1f} cm from the target, tilted {np.rad2deg(tilt):.0f}°"
