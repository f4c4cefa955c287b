"""Parameters of the perception stage (paper section III-A/B), one dataclass per step.

Every field has a default and a unit. The defaults are the values our evaluation uses
(`tools/eval_perception.py`); the paper gives only σ's meaning, not its value.
"""


from dataclasses import dataclass, field


@dataclass
class SegmentationConfig:
    """Table plane (RANSAC) and object clusters (DBSCAN) from a depth cloud."""

    plane_distance: float = 0.005  # RANSAC inlier distance to the table plane [m].
    ransac_points: int = 20000  # RANSAC runs on at most this many points (a stride subsample).
    ransac_iterations: int = 300  # RANSAC iterations per plane.
    max_planes: int = 3  # planes tried before giving up on finding a horizontal table.
    max_table_tilt_deg: float = 25.0  # a table normal is at most this far from world +z [deg].
    min_table_fraction: float = 0.05  # a table holds at least this share of the cloud.
    # Object points are this far above the plane [m]: about 2.2 σ of the table's height noise
    # through a triangulating camera at 1 m (the D415 model, sensor_model: σ = 1.8 mm on the
    # table at the default viewpoint, voxel averaging does not lower it, 0.1 % of the table's
    # voxels lie 5.7 mm above it). Flat parts thinner than this (blades lying flat, 2–3 mm) are
    # not told from the table by a point's height alone: `thin_cell` patches are.
    min_object_height: float = 0.004
    # Thin objects (segmentation.raised_cells): the points below min_object_height are gridded in
    # cells of this side on the table [m] (about 20 pixels each at 1 m: the median's noise is a
    # quarter of a pixel's); a cell whose median height exceeds `thin_significance` standard
    # errors of that median (from the table's own noise at the cell's range), and at least
    # `thin_min_height`, is part of an object: all its points are object points.
    thin_cell: float = 0.01
    thin_significance: float = 3.0  # [standard errors] one-sided: 0.13 % of the table's cells;
    # alone they make no object (a cluster needs min_cluster_points voxels).
    thin_min_height: float = 0.001  # [m] half the thinnest object to be seen (2 mm)
    thin_min_cell_points: int = 6  # a cell with fewer points says nothing
    # The table's noise at an object's foot (segmentation.foot_noise): a voxel within this many
    # σ of the table's height noise (4.5σ: one-sided 3·10⁻⁶ of a normal; 8 mm at 1 m through the
    # D415), out from the footprint of the object above that band, on table that is not raised,
    # is not the object. 0 keeps every voxel DBSCAN joined.
    foot_noise_sigmas: float = 4.5
    # A raised cell's points never join an object the height threshold sees, unless that object
    # lies flat: the median height of its points is below this [m] (a blade whose noise crosses
    # the threshold here and there; a can's or a handle's is far above it).
    thin_max_height: float = 0.01
    max_object_height: float = 0.6  # ... and at most this far [m].
    table_margin: float = 0.0  # objects' points may lie this far outside the table's extent [m].
    voxel_size: float = 0.004  # object points are averaged per voxel of this side [m] ...
    max_object_points: int = 2000  # ... or of a larger side that leaves about this many.
    cluster_eps: float = 0.012  # DBSCAN neighbourhood radius [m].
    cluster_min_points: int = 4  # DBSCAN core-point neighbour count (voxels).
    min_cluster_points: int = 40  # smaller clusters are noise (voxels).
    # Clusters that meet in the image — touching (within 2 px), or across at most lost_bridge_px
    # pixels on each side that the sensor lost (no depth: a depth edge's dropout and shadow, a
    # grazing surface) — are one object whose connection the camera did not see (a pan's handle
    # whose root hides behind the rim; a ladle's handle behind its bowl's rim, under its dropout
    # band) when they are at most merge_max_gap apart in space (segmentation._merge_occluded,
    # _merge_through_lost); table seen between them keeps them apart. Fitted on the training
    # objects' frames of the executed generalization suites (the station's camera through the
    # D415 model; 91 lying views): the smallest gap of 0.05/0.07/0.08/0.10/0.12 m, then the
    # smallest bridge of 0/4/8/12 px, that leave none of them in pieces (0.05 m and no bridge:
    # 6 in two); no two of 69 multi-object frames (S_ROBOT, the pourOut scenes) merge up to
    # 0.12 m and 8 px.
    merge_max_gap: float = 0.10  # [m]
    lost_bridge_px: int = 4  # [px] (0: off)
    # Two clusters whose tops lie on one circle are the two sides of one open container whose rim
    # between them the camera lost (segmentation._merge_shared_rims): their tops (the points within
    # rim_band of each cluster's highest) at heights within rim_band of each other, one circle
    # through both with an RMS distance of at most rim_fit_rms [m] (twice the D415's 2 mm noise at
    # 1 m).
    rim_band: float = 0.01  # [m]
    rim_fit_rms: float = 0.004  # [m]
    border_margin_px: int = 2  # a cluster with a pixel this close to the image edge is cut [px].
    drop_border_objects: bool = True  # drop objects cut by the image border (else keep them).
    seed: int = 0  # seeds the table's RANSAC (a generator made from it for each table search;
    # the only randomness of the perception stage: DBSCAN is deterministic). In a scenario the
    # RANSAC seed is this plus the scenario's random_seed.


@dataclass
class CompletionConfig:
    """Symmetry-based shape completion (paper III-A) and the circle test for handles (III-B)."""

    sigma: float = 0.9  # top region: points with height above σ·d_z (paper's σ ∈ [0, 1]).
    normal_neighbours: int = 12  # k of the k-nn normal estimate.
    circle_bins: int = 36  # angular bins of the outline over 360° (folded to 180°).
    circle_tolerance: float = 0.08  # outline radius within ±this share of R is on the circle.
    min_circle_fraction: float = 0.85  # share of non-handle outline bins on the circle.
    min_circle_coverage: float = 0.9  # share of folded outline bins that must hold points.
    handle_min_protrusion: float = 0.1  # a handle reaches at least (1 + this)·R from the axis ...
    handle_min_reach: float = 0.012  # ... and at least this far beyond the circle [m].
    max_handle_fraction: float = 0.45  # a handle covers at most this share of the folded outline.
    min_handle_points: int = 8  # fewer points outside the circle are noise, not a handle.
    # Free space (`completion.seen_free`): a rotated point is dropped where the camera saw
    # through it, i.e. no observed point lies within `free_space_radius` of its line of sight
    # nearer than `free_space_margin` behind it: 1.5 and 1 voxels of
    # SegmentationConfig.voxel_size (4 mm), the averaged points' spacing and depth error. Chosen
    # on training objects' perceived views (D415 model, yaw 30°, 38 views of 24 objects, every
    # resting pose): of 43,518 rotated points it drops 3,516, of which 8 lie within 4 mm of the
    # true surface (8 mm / 8 mm: 2,292 and 1; 5 / 3 mm: 4,154 and 24). 0 radius: no carving.
    free_space_radius: float = 0.006  # [m] across the line of sight, at the object's range.
    free_space_margin: float = 0.004  # [m] along it.


@dataclass
class PoseConfig:
    """Upright / sideways / upside-down and its likelihood (see `tg_drake.perception.pose`)."""

    cavity_depth: float = 0.01  # a cavity point lies this far below the rim, at least [m] ...
    cavity_depth_fraction: float = 0.12  # ... or this share of the object height if larger.
    min_cavity_share: float = 0.25  # share of far-side points inside the rim that are deep.
    min_cavity_points: int = 6  # at least this many deep points make a cavity.
    min_interior_share: float = 0.12  # the `interior_seen` observation: this share of the
    # visible body points faces into the object (pose.interior_seen).
    neck_ratio: float = 0.6  # top radius below this share of the base radius is a neck ...
    neck_body_ratio: float = 0.95  # ... over a body this wide at mid-height, or a straight
    # lower wall under a shoulder (pose.shoulder) (else a taper).
    taper_ratio: float = 0.95  # top radius below this share of the base radius is a taper ...
    taper_body_ratio: float = 0.98  # ... narrowing already at mid-height (a can's rim does not)
    strong_taper_ratio: float = 0.9  # ... or narrowing this much at the top.
    calibration: str = ""  # a pose likelihood file (tools/calibrate_pose.py writes one); "" =
    # the shipped tg_drake/data/pose_likelihood.json


@dataclass
class PartConfig:
    """Semantic parts (paper III-B)."""

    tool_max_thickness: float = 0.04  # a tool's cross-section is thinner than this ... [m]
    tool_thin_fraction: float = 0.55  # ... over at least this share of its length.
    tool_handle_ratio: float = 1.5  # a handle reaching beyond this many body diameters makes
    # a long-handled tool lying on its head (a ladle), not a pan.
    top_fraction: float = 1.0 / 3.0  # share of the axis length labelled top.
    bottom_fraction: float = 1.0 / 3.0  # share of the axis length labelled bottom.
    profile_bins: int = 30  # bins along the axis for the tool's cross-section profile.
    coverage_bins: int = 5  # bins per part for the visible-coverage part probability.


@dataclass
class PregraspConfig:
    """Pre-grasp hypotheses: two gripper poses per face of each part box (paper III-B)."""

    grasp_depth: float = 0.02  # the grasp point lies this far inside the face [m] (at most
    # half the box depth): the fingers straddle the part's outer layer.
    # Rim grasps (ours, beyond the paper's box faces): an open container whose top part is wider
    # than the gripper opens (a bowl, a pot) can still be taken by its wall, one finger inside.
    rim_min_width: float = 0.10  # a top part at least this wide both ways gets rim grasps [m].
    rim_azimuths: int = 8  # rim grasps spread evenly around the axis.
    rim_depth: float = 0.005  # the grasp point lies this far below the rim [m]: the inner
    # finger stays high, clear of the container's floor.
    rim_wall: float = 0.004  # the grasp point lies this far inside the outer radius [m] (about
    # half a wall's thickness).
    # Grasps along a long part (ours, beyond the paper's face centres): a part box whose longest
    # side is at least `along_min_length` and twice its others (a handle) also gets the face
    # grasps that close across it shifted along it by ± `along_fraction` of its half length, so
    # that the planner can hold a hammer near its heavy head rather than at its handle's middle.
    along_min_length: float = 0.08  # [m]
    along_fraction: float = 0.5


@dataclass
class PerceptionConfig:
    segmentation: SegmentationConfig = field(default_factory=SegmentationConfig)
    completion: CompletionConfig = field(default_factory=CompletionConfig)
    pose: PoseConfig = field(default_factory=PoseConfig)
    parts: PartConfig = field(default_factory=PartConfig)
    pregrasp: PregraspConfig = field(default_factory=PregraspConfig)
