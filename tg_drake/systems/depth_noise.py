"""The depth sensor model as a Drake system, between a rendered depth image and perception.

The errors themselves are the core's (`tg_drake.perception.sensor_model.apply_sensor`); this
system only reads the image and the time, and names the capture.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem
from pydrake.systems.sensors import CameraInfo, ImageDepth32F

from tg_drake.perception.geometry import Intrinsics
from tg_drake.perception.sensor_model import SensorModel, apply_sensor, capture_index


class DepthNoise(LeafSystem):
    """What a real depth camera would measure of a rendered depth image.

    .. pydrake_system::

        name: DepthNoise
        input_ports:
        - depth_image
        output_ports:
        - depth_image

    Both ports carry an ImageDepth32F of the size given by `camera_info` [m]; the output is 0
    where the sensor gives no depth. The draws are seeded by `seed` and the index of the latest
    frame the camera has captured (`fps` frames per second from `capture_offset` [s]), so the
    output is the same on every evaluation within one frame period and differs between frames.
    """

    def __init__(self, camera_info: CameraInfo, model: SensorModel, *, seed: int = 0,
                 fps: float = 10.0, capture_offset: float = 0.0):
        super().__init__()
        self._intrinsics = Intrinsics.from_camera_info(camera_info)
        self._model = model
        self._seed = int(seed)
        self._fps = float(fps)
        self._offset = float(capture_offset)
        capture_index(self._offset, self._fps, self._offset)  # checks the frame rate
        w, h = camera_info.width(), camera_info.height()
        self._in = self.DeclareAbstractInputPort("depth_image",
                                                 AbstractValue.Make(ImageDepth32F(w, h)))
        self.DeclareAbstractOutputPort(
            "depth_image", lambda: AbstractValue.Make(ImageDepth32F(w, h)), self._calc,
            prerequisites_of_calc={self.input_port_ticket(self._in.get_index()),
                                   self.time_ticket()})

    @property
    def model(self) -> SensorModel:
        return self._model

    def _calc(self, context, output):
        image: ImageDepth32F = self._in.Eval(context)
        capture = capture_index(context.get_time(), self._fps, self._offset)
        noisy = apply_sensor(np.asarray(image.data)[..., 0], self._intrinsics, self._model,
                             seed=self._seed, capture=capture)
        out = output.get_mutable_value()
        out.resize(image.width(), image.height())
        out.mutable_data[:, :, 0] = noisy
