"""The table: a compliant-hydroelastic top on four legs, sized by the scenario's `table_size`.

One source of the table's facts. `table_sdf(size)` writes its model; `add_table` adds it to a plant
with its top frame `table_top` welded at X_WT (the station and the planning plant both call it), and
tools/make_robot_models.py writes models/table/table.sdf (the default size, for a scenario's own
directives) from the same function.

Frame `table_top`: origin at the centre of the top surface, z up, x away from the robot. The top is
a box of `size` × TABLE_THICKNESS below the surface; the legs (visual only) stand TABLE_LEG_INSET
in from each edge and reach the floor TABLE_HEIGHT below the surface, whatever the size.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import AddCompliantHydroelasticProperties, Box, ProximityProperties
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex, SpatialInertia

# Where the table-top frame T sits in the world (its surface at the iiwa base height). Its centre
# is 0.75 m in front of the base: side grasps at 0.7–0.9 m and top grasps at 0.45–0.8 m are within
# reach there (an IK sweep over grasp heights 0.04–0.25 m; see tools notes in the README).
X_WT_DEFAULT = RigidTransform([0.75, 0.0, 0.0])
TABLE_SIZE = (0.8, 1.2)  # [m] default top x (depth, away from the robot) × y (width)
TABLE_THICKNESS = 0.04  # [m] of the top slab
TABLE_HEIGHT = 0.4  # [m] table-top surface above the floor
FLOOR_MARGIN = 1.0  # [m] how far past each edge of the table the floor reaches (it is there for
# the contents' spheres only: station.add_contents_floor)
FLOOR_THICKNESS = 1.0  # [m] of that floor's slab (a sphere shot down at 30 m/s still meets it)
TABLE_MASS = 20.0  # [kg] of the top (welded to the world: it only fills the model)
TABLE_LEG_WIDTH = 0.05  # [m] square legs
TABLE_LEG_INSET = 0.05  # [m] from a top edge to a leg's centre line
# The compliant top, measured to hold objects at rest (docs/design.md, "Simulation settings"):
# hydroelastic modulus [Pa], mesh resolution hint [m], Hunt–Crossley dissipation [s/m], friction.
TABLE_HYDRO = dict(modulus=1e7, resolution=0.1, dissipation=3.0, mu=0.5)
MIN_TABLE_SIZE = 2 * TABLE_LEG_INSET + TABLE_LEG_WIDTH  # [m] below this the legs stick out


def _box_inertia(mass, size):
    x, y, z = size
    return (mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12)


def table_sdf(size=TABLE_SIZE) -> str:
    """The table model (SDFormat text) with a top of `size` = (x, y) [m]."""
    tx, ty = (float(v) for v in size)
    tz = TABLE_THICKNESS
    legs = []
    for i, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        pose = (f"{sx * (tx / 2 - TABLE_LEG_INSET):.6g} {sy * (ty / 2 - TABLE_LEG_INSET):.6g} "
                f"{-(TABLE_HEIGHT + tz) / 2:.6g} 0 0 0")
        legs.append(f'      <visual name="leg_{i}">\n        <pose>{pose}</pose>\n'
                    f"        <geometry><box><size>{TABLE_LEG_WIDTH} {TABLE_LEG_WIDTH} "
                    f"{TABLE_HEIGHT - tz}</size></box></geometry>\n"
                    "        <material><diffuse>0.45 0.3 0.2 1</diffuse></material>\n"
                    "      </visual>\n")
    top_pose = f"0 0 {-tz / 2} 0 0 0"
    ixx, iyy, izz = _box_inertia(TABLE_MASS, (tx, ty, tz))
    h = TABLE_HYDRO
    return (
        '<?xml version="1.0"?>\n'
        "<!-- Table, written by tools/make_robot_models.py. Frame `table_top`: origin at the "
        "centre of\n"
        "     the top surface, z up. The top is a compliant-hydroelastic box;\n"
        "     the legs are visual only. Weld `table_top` to the world. Do not edit by hand. -->\n"
        '<sdf version="1.9" xmlns:drake="http://drake.mit.edu">\n'
        '  <model name="table">\n'
        '    <link name="table_top">\n'
        f"      <inertial>\n        <pose>{top_pose}</pose>\n        <mass>{TABLE_MASS}</mass>\n"
        f"        <inertia><ixx>{ixx:.6g}</ixx><ixy>0</ixy><ixz>0</ixz><iyy>{iyy:.6g}</iyy>"
        f"<iyz>0</iyz><izz>{izz:.6g}</izz></inertia>\n      </inertial>\n"
        '      <visual name="top_visual">\n'
        f"        <pose>{top_pose}</pose>\n"
        f"        <geometry><box><size>{tx:g} {ty:g} {tz}</size></box></geometry>\n"
        "        <material><diffuse>0.82 0.78 0.7 1</diffuse></material>\n      </visual>\n"
        + "".join(legs)
        + '      <collision name="top_collision">\n'
        f"        <pose>{top_pose}</pose>\n"
        f"        <geometry><box><size>{tx:g} {ty:g} {tz}</size></box></geometry>\n"
        "          <drake:proximity_properties>\n"
        "            <drake:compliant_hydroelastic/>\n"
        f"            <drake:hydroelastic_modulus>{h['modulus']:.6g}</drake:hydroelastic_modulus>\n"
        f"            <drake:mesh_resolution_hint>{h['resolution']}</drake:mesh_resolution_hint>\n"
        f"            <drake:hunt_crossley_dissipation>{h['dissipation']}"
        "</drake:hunt_crossley_dissipation>\n"
        f"            <drake:mu_dynamic>{h['mu']}</drake:mu_dynamic>\n"
        f"            <drake:mu_static>{h['mu']}</drake:mu_static>\n"
        "          </drake:proximity_properties>\n"
        "      </collision>\n    </link>\n  </model>\n</sdf>\n")


def add_table(plant: MultibodyPlant, size, X_WT: RigidTransform) -> ModelInstanceIndex:
    """Adds the table of top `size` (x, y) [m] to `plant` (before Finalize), its `table_top` frame
    welded to the world at X_WT. The model instance is named "table"."""
    (table,) = Parser(plant).AddModelsFromString(table_sdf(size), "sdf")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("table_top", table), X_WT)
    return table


def table_size_problem(size) -> str | None:
    """What is wrong with a `table_size` value, or None."""
    if len(size) != 2 or not all(np.isfinite(v) for v in size):
        return f"table_size must be two finite numbers (x, y) [m], got {list(size)}"
    if min(size) < MIN_TABLE_SIZE:
        return (f"table_size {list(size)} is too small: each side at least {MIN_TABLE_SIZE:g} m "
                "(the legs stand inside the top)")
    return None


SURFACE_MASS = 1.0  # [kg] of a surface box (welded to the table: it only fills the model)
SURFACE_COLOR = (0.55, 0.42, 0.3, 1.0)  # RGBA of a surface's visual


def surface_body_name(name: str) -> str:
    """The body of surface `name` in the table's model instance."""
    return f"surface_{name}"


def add_surfaces(plant: MultibodyPlant, table: ModelInstanceIndex, surfaces) -> list:
    """Adds each surface (`tg_drake.scenario.SurfaceConfig`: `name`, centre `xy` in the table
    frame, `size` (x, y, height) [m]) to the table's model instance, before Finalize: a box
    standing on the table top, welded to it, compliant-hydroelastic like the top (TABLE_HYDRO).
    Returns their bodies."""
    top = plant.GetFrameByName("table_top", table)
    h = TABLE_HYDRO
    bodies = []
    for s in surfaces:
        sx, sy, sz = (float(v) for v in s.size)
        body = plant.AddRigidBody(surface_body_name(s.name), table,
                                  SpatialInertia.SolidBoxWithMass(SURFACE_MASS, sx, sy, sz))
        box = Box(sx, sy, sz)
        props = ProximityProperties()
        AddCompliantHydroelasticProperties(h["resolution"], h["modulus"], props)
        props.AddProperty("material", "hunt_crossley_dissipation", h["dissipation"])
        props.AddProperty("material", "coulomb_friction", CoulombFriction(h["mu"], h["mu"]))
        plant.RegisterCollisionGeometry(body, RigidTransform(), box, f"surface_{s.name}", props)
        plant.RegisterVisualGeometry(body, RigidTransform(), box, f"surface_{s.name}_visual",
                                     np.array(SURFACE_COLOR))
        plant.WeldFrames(top, body.body_frame(), RigidTransform([float(s.xy[0]),
                                                                 float(s.xy[1]), sz / 2]))
        bodies.append(body)
    return bodies
