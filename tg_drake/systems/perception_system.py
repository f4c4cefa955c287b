"""The perception stage as Drake systems (paper section III-A/B).

`PerceptionSystem` describes the objects on the table from a rendered depth image;
`GroundTruthPerception` gives the same output from the object library's labels, for the
synthetic (perfect-perception) evaluation.

Both latch their result: the scene description is declared abstract state, written by events
only — an initialization event (perceive at the start) and, when the ``perception_request``
input holds a value other than the one last served, a periodic event that perceives again. The
outputs depend on that state alone, so the arm moving into the camera's view changes nothing
downstream, and every later stage's cache stays valid until perception runs again.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.systems.framework import EventStatus, LeafSystem
from pydrake.systems.sensors import CameraInfo, ImageDepth32F

from tg_drake.errors import PerceptionError
from tg_drake.perception.config import PerceptionConfig
from tg_drake.perception.geometry import Intrinsics
from tg_drake.perception.ground_truth import describe_library_object
from tg_drake.perception.pipeline import describe_scene
from tg_drake.types import PerceptionStatus, SceneDescription

# How often a new perception_request is looked for [s], and the time of the first look [s]. The
# offset keeps the looks off the plant's step grid (time steps of 0.1, 0.5, 1, 2, 5, 10 ms): Drake
# rewrites the state of every system with an update event in a step where any update does
# something, and the plant's does at each of its steps, so a look on the grid would invalidate
# the latched state, and every downstream cache, at every look.
REQUEST_PERIOD = 0.05
REQUEST_OFFSET = 0.01234


def _empty_scene() -> SceneDescription:
    return SceneDescription(objects=[], X_WT=np.eye(4))


@dataclasses.dataclass(frozen=True)
class _Latch:
    """The perception systems' abstract state. Immutable: an event replaces it."""

    scene: SceneDescription | None = None  # the latest perceived scene; None if it failed
    failure: PerceptionError | None = None  # why the latest perception failed
    status: PerceptionStatus = PerceptionStatus(ok=False)

    def __deepcopy__(self, memo):
        return self  # immutable: Drake's copies of abstract values may share it


class _LatchedPerception(LeafSystem):
    """The latch shared by both perception systems: state, request port, events and outputs.

    A subclass declares its own inputs, then calls `_declare_latch`, and implements `_perceive`.
    """

    def _declare_latch(self):
        self._request_port = self.DeclareAbstractInputPort(
            "perception_request", AbstractValue.Make(0))
        self._latch = self.DeclareAbstractState(AbstractValue.Make(_Latch()))
        self.DeclareInitializationUnrestrictedUpdateEvent(self._on_initialization)
        # Periodic rather than per step: a per-step look shares every step with the plant's
        # update, which rewrites this state; a periodic one off the plant's grid that finds no
        # new request returns DidNothing and leaves the state, and every downstream cache, as
        # they are. A request waits at most REQUEST_PERIOD.
        self.DeclarePeriodicUnrestrictedUpdateEvent(REQUEST_PERIOD, REQUEST_OFFSET,
                                                    self._on_look)
        on_latch = {self.abstract_state_ticket(self._latch)}
        self._scene_port = self.DeclareAbstractOutputPort(
            "scene_description", lambda: AbstractValue.Make(_empty_scene()), self._calc_scene,
            prerequisites_of_calc=on_latch)
        self._status_port = self.DeclareAbstractOutputPort(
            "perception_status", lambda: AbstractValue.Make(PerceptionStatus(ok=False)),
            self._calc_status, prerequisites_of_calc=on_latch)

    def _perceive(self, context) -> SceneDescription:
        """The scene from this system's inputs; each perception system defines it (raises
        PerceptionError when there is nothing to describe)."""
        raise NotImplementedError(f"{type(self).__name__} does not define _perceive")

    def get_perception_request_input_port(self):
        return self._request_port

    def get_scene_description_output_port(self):
        return self._scene_port

    def get_perception_status_output_port(self):
        return self._status_port

    # Events.
    def _request(self, context) -> int:
        if not self._request_port.HasValue(context):
            return 0
        value = self._request_port.Eval(context)
        if isinstance(value, bool) or not isinstance(value, int | np.integer):
            raise TypeError(f"{self.get_name()}: perception_request must be an int counter, "
                            f"got {value!r}")
        return int(value)

    def _on_initialization(self, context, state):
        self._latch_perception(context, state, self._request(context))
        return EventStatus.Succeeded()

    def _on_look(self, context, state):
        if not self._request_port.HasValue(context):
            return EventStatus.DidNothing()
        request = self._request(context)
        if request == self._latched(context).status.request:
            return EventStatus.DidNothing()
        self._latch_perception(context, state, request)
        return EventStatus.Succeeded()

    def _latch_perception(self, context, state, request: int):
        count = self._latched(context).status.n_perceptions + 1
        t0 = time.perf_counter()
        try:
            scene, failure = self._perceive(context), None
        except PerceptionError as e:  # latched: reported on perception_status, not raised here
            scene, failure = None, e
        status = PerceptionStatus(ok=failure is None, error="" if failure is None else str(failure),
                                  wall_time=time.perf_counter() - t0, n_perceptions=count,
                                  request=request, t_perceived=context.get_time())
        state.get_mutable_abstract_state(self._latch).set_value(
            _Latch(scene=scene, failure=failure, status=status))

    def _latched(self, context) -> _Latch:
        return context.get_abstract_state(self._latch).get_value()

    # Outputs: the latch only.
    def _calc_scene(self, context, output):
        latch = self._latched(context)
        if latch.status.n_perceptions == 0:
            # A context no initialization event has run on (no Simulator.Initialize yet):
            # perceive once on demand, latching nothing, so that a fresh context can be read.
            output.set_value(self._perceive(context))
            return
        if latch.failure is not None:
            e = latch.failure
            raise PerceptionError(e.message, file=e.file, line=e.line, field=e.field)
        output.set_value(latch.scene)

    def _calc_status(self, context, output):
        output.set_value(self._latched(context).status)


class PerceptionSystem(_LatchedPerception):
    """Scene description from a depth image: table, objects, completion, pose, parts, pre-grasps.

    .. pydrake_system::

        name: PerceptionSystem
        input_ports:
        - depth_image
        - camera_pose
        - perception_request (optional)
        output_ports:
        - scene_description
        - perception_status

    ``depth_image`` is an ImageDepth32F (metres; +inf / 0 where there is no return) of the size
    given by `camera_info`; ``camera_pose`` is the RigidTransform X_WC of the depth camera
    (Drake's camera frame: X right, Y down, Z forward). ``perception_request`` (int) is a
    counter: when it holds a value other than the one last served, the system perceives again at
    its next look (every REQUEST_PERIOD = 0.05 s); unconnected, it perceives at initialization
    only.

    Perception runs in events and its result is latched: at initialization, and on a request.
    ``scene_description`` is the latched `SceneDescription`, one `ObjectDescription` per object
    on the table, ordered along the table frame's x; it depends on the latched state only, never
    on the live image. A frame without a table, or whose objects are all cut by the image border,
    is latched as a failure: evaluating ``scene_description`` then raises that PerceptionError,
    and ``perception_status`` (a `PerceptionStatus`: ok, error, wall time, count, request served)
    reports it without raising. Before the first initialization event (a fresh context, before
    `Simulator.Initialize`), ``scene_description`` perceives the current frame on demand and
    latches nothing.
    """

    def __init__(self, camera_info: CameraInfo, config: PerceptionConfig | None = None):
        super().__init__()
        self._intrinsics = Intrinsics.from_camera_info(camera_info)
        self._config = config if config is not None else PerceptionConfig()
        self._depth_port = self.DeclareAbstractInputPort(
            "depth_image", AbstractValue.Make(ImageDepth32F(camera_info.width(),
                                                            camera_info.height())))
        self._pose_port = self.DeclareAbstractInputPort(
            "camera_pose", AbstractValue.Make(RigidTransform()))
        self._declare_latch()

    @property
    def intrinsics(self) -> Intrinsics:
        return self._intrinsics

    @property
    def config(self) -> PerceptionConfig:
        """The perception parameters this system runs with."""
        return self._config

    def get_depth_image_input_port(self):
        return self._depth_port

    def get_camera_pose_input_port(self):
        return self._pose_port

    def _perceive(self, context) -> SceneDescription:
        image: ImageDepth32F = self._depth_port.Eval(context)
        X_WC: RigidTransform = self._pose_port.Eval(context)
        if image.width() != self._intrinsics.width or image.height() != self._intrinsics.height:
            raise PerceptionError(
                f"depth_image is {image.width()}×{image.height()} but the camera info says "
                f"{self._intrinsics.width}×{self._intrinsics.height}")
        return describe_scene(image.data, self._intrinsics, X_WC.GetAsMatrix4(), self._config)


class GroundTruthPerception(_LatchedPerception):
    """The scene description of library objects at known poses, from their labelled meshes.

    .. pydrake_system::

        name: GroundTruthPerception
        input_ports:
        - perception_request (optional)
        - body_poses (optional)
        output_ports:
        - scene_description
        - perception_status

    Each object's surface is sampled uniformly (``spacing`` apart) with its ground-truth part
    labels and outward normals, at its world pose X_WO (the library object frame); its pose
    label is given or derived from X_WO, its parts have probability 1. The description is made
    once, when the system is built, and latched like `PerceptionSystem`'s (at initialization and
    on a ``perception_request``), with the same ``perception_status``. A request after the first
    (a value > 0) with ``body_poses`` connected (the plant's body poses; `body_indices` gives
    each object's body) describes the objects where they are now, their pose labels derived from
    those poses (a place-and-regrasp moved the target). For the synthetic evaluation only: the
    pipeline's `PerceptionSystem` never reads ground truth.
    """

    def __init__(self, object_ids: list[str], X_WO: list, *, X_WT=None, poses=None,
                 containments=None, spacing: float = 0.004, seed: int = 0, body_indices=None):
        super().__init__()
        if len(object_ids) != len(X_WO):
            raise PerceptionError(
                f"GroundTruthPerception got {len(object_ids)} object ids but {len(X_WO)} poses")
        X_WT = np.eye(4) if X_WT is None else _matrix(X_WT)
        poses = poses if poses is not None else [None] * len(object_ids)
        containments = containments if containments is not None else [None] * len(object_ids)
        self._ids, self._X_WT, self._spacing, self._seed = list(object_ids), X_WT, spacing, seed
        self._containments = list(containments)
        self._bodies = None if body_indices is None else [int(i) for i in body_indices]
        self._poses_port = self.DeclareAbstractInputPort(
            "body_poses", AbstractValue.Make([RigidTransform()]))
        rng = np.random.default_rng(seed)
        self._scene = SceneDescription(objects=[
            describe_library_object(i, _matrix(X), X_WT, spacing=spacing, rng=rng, pose=p,
                                    containment=c)
            for i, X, p, c in zip(object_ids, X_WO, poses, containments, strict=False)], X_WT=X_WT)
        self._declare_latch()

    def _perceive(self, context) -> SceneDescription:
        request = self._request(context)
        if request == 0 or self._bodies is None or not self._poses_port.HasValue(context):
            return self._scene
        poses = self._poses_port.Eval(context)  # where the objects are now
        rng = np.random.default_rng(self._seed + request)
        return SceneDescription(objects=[
            describe_library_object(i, _matrix(poses[b]), self._X_WT, spacing=self._spacing,
                                    rng=rng, containment=c)
            for i, b, c in zip(self._ids, self._bodies, self._containments, strict=True)],
            X_WT=self._X_WT)


def _matrix(X) -> np.ndarray:
    return X.GetAsMatrix4() if isinstance(X, RigidTransform) else np.asarray(X, float)
