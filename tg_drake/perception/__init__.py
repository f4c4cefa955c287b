"""Perception stage (paper section III-A/B): depth image → `tg_drake.types.SceneDescription`.

Modules, each pure (arrays in, arrays out; no Drake systems):

- `geometry`: pinhole back-projection in Drake's camera convention, rigid transforms, normals,
  voxel averaging;
- `segmentation`: table plane (RANSAC) and object clusters (DBSCAN) of a depth frame;
- `completion`: the paper's symmetry-based completion and circle test (handles);
- `pose`: upright / sideways / upside-down with a likelihood;
- `parts`: top, middle, bottom, handle, usable area, with probabilities and part boxes;
- `pregrasp`: two gripper poses per face of each part box (`WSG_GRASP_POINT_G`);
- `pipeline`: `describe_scene` (depth frame) and `describe_object` / `describe_cloud` (points);
- `ground_truth`: the same description from the object library's labels (synthetic setting);
- `plot`: part-coloured PNGs; `synthetic`: known shapes and ray-cast depth for tests;
- `render`: a library object alone on a table, ray cast from the default camera and perceived
  (how the evaluation's perceived suites and the kernel database's perceived entries see it);
- `config`: every parameter, one dataclass per step; `bench`: the speed figures.

The Drake systems are in `tg_drake.systems.perception_system`.
"""
