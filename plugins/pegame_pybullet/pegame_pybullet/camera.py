"""The pursuer's RGB-D camera: a pinhole rendered by PyBullet's TinyRenderer.

Geometry: horizontal field of view ``fov`` (rad) over ``width`` pixels, square pixels, the
optical axis through the image centre; so the focal length is f = (width / 2) / tan(fov / 2)
px and the vertical field of view is 2 atan(tan(fov / 2) * height / width). TinyRenderer
samples pixel (row i, col j) at the image point (j, i + 1), a pixel corner, not at its
centre (j + 1/2, i + 1/2) (measured: edges and floor depth match to 1e-6); the intrinsics,
in the pixel-centre convention of :class:`pegame.api.SensorFrame`, therefore put the
principal point at (width / 2 + 1/2, height / 2 - 1/2). The optical
centre sits ``mount_height`` m above the floor on the robot's vertical axis, looking along
its heading, pitched ``tilt`` rad down (the paper's human-robot setting tilts it pi/8,
Sec. "Simulation based validation"). Near and far clip planes are ``near`` and ``far`` m
along the optical axis.

Depth is metric z (distance along the optical axis), linearised from the OpenGL z-buffer
value b in [0, 1]: z = far * near / (far - b (far - near)); pixels where nothing is
rendered (beyond the far plane) get inf, as a depth camera gives no return there.

The floor (the plane z = 0) is not rasterised but composited in closed form: TinyRenderer
spends ~0.14 us per shaded pixel and the floor fills about half the image, while its depth
per pixel depends only on the camera's height and tilt, not on where the robot is. Nothing
stands below the floor, so every rendered pixel occludes it: a pixel shows the floor
exactly when nothing else was rendered there and its ray meets z = 0 within the clip range.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet

from pegame.types import Pose
from pegame_pybullet.client import Client

FLOOR_RGB = (107, 107, 107)  # uint8: the floor body as TinyRenderer shades it (measured)


class DepthCamera:
    """Renders (rgb, depth, segmentation) for a camera pose; see the module docstring."""

    def __init__(
        self,
        client: Client,
        width: int,
        height: int,
        fov: float,
        near: float,
        far: float,
        mount_height: float,
        tilt: float,
    ) -> None:
        self.client = client
        self.width, self.height = width, height
        self.near, self.far = near, far
        self.mount_height, self.tilt = mount_height, tilt
        focal = 0.5 * width / math.tan(0.5 * fov)
        self.intrinsics = np.array(
            [[focal, 0.0, 0.5 * width + 0.5], [0.0, focal, 0.5 * height - 0.5], [0.0, 0.0, 1.0]]
        )
        self.intrinsics.setflags(write=False)
        vertical_fov = 2.0 * math.atan(math.tan(0.5 * fov) * height / width)
        self._projection = pybullet.computeProjectionMatrixFOV(
            math.degrees(vertical_fov), width / height, near, far
        )
        self.floor_depth = self._floor_depth()

    def _floor_depth(self) -> np.ndarray:
        """(H, W) float32 z-depth (m) of the floor at each pixel, inf where the pixel's ray
        misses the floor within [near, far]. A ray through pixel centre (u, v) reaches
        depth z at height mount_height - z (sin(tilt) + cos(tilt) (v - cy) / f)."""
        focal, cy = self.intrinsics[1, 1], self.intrinsics[1, 2]
        rows = (np.arange(self.height) + 0.5 - cy) / focal
        descent = math.sin(self.tilt) + math.cos(self.tilt) * rows  # height lost per metre of z
        with np.errstate(divide="ignore"):
            z = np.where(descent > 0, self.mount_height / descent, np.inf)
        z[(z < self.near) | (z > self.far)] = np.inf
        depth = np.repeat(z[:, None], self.width, axis=1).astype(np.float32)
        depth.setflags(write=False)
        return depth

    def camera_to_map(self, pose: Pose) -> np.ndarray:
        """(4, 4) transform from the optical frame (x right, y down, z forward) to the map
        frame (z up), for the robot at ``pose``."""
        c, s = math.cos(pose.theta), math.sin(pose.theta)
        ct, st = math.cos(self.tilt), math.sin(self.tilt)
        forward = np.array([ct * c, ct * s, -st])
        right = np.array([s, -c, 0.0])
        down = np.cross(forward, right)
        transform = np.eye(4)
        transform[:3, 0], transform[:3, 1], transform[:3, 2] = right, down, forward
        transform[:3, 3] = (pose.x, pose.y, self.mount_height)
        return transform

    def render(
        self, transform: np.ndarray, floor_label: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """rgb (H, W, 3) uint8, depth (H, W) float32 m, segmentation (H, W) int32 body ids
        (-1 for nothing, ``floor_label`` for the floor) of the camera at ``transform`` (from
        :meth:`camera_to_map`); the floor body itself must be out of view."""
        eye = transform[:3, 3]
        view = pybullet.computeViewMatrix(eye, eye + transform[:3, 2], -transform[:3, 1])
        # pybullet built with numpy (the PyPI wheels) returns fresh (H, W, 4) uint8, (H, W)
        # float32 and (H, W) int32 arrays.
        _, _, rgba, zbuffer, seg = self.client.getCameraImage(
            self.width,
            self.height,
            view,
            self._projection,
            shadow=0,
            renderer=pybullet.ER_TINY_RENDERER,
        )
        rgb = rgba[:, :, :3].copy()
        depth = self.far * self.near / (self.far - zbuffer * np.float32(self.far - self.near))
        empty = seg < 0
        depth[empty] = np.inf
        floor = empty & np.isfinite(self.floor_depth)
        rgb[floor] = FLOOR_RGB
        depth[floor] = self.floor_depth[floor]
        seg[floor] = floor_label
        return rgb, depth, seg
