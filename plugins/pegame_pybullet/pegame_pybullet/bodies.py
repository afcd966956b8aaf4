"""The pursuer as a PyBullet body built from primitive shapes, and the agents' colours.

Each body's frame has its origin on the floor under the agent's centre, x forward and z up,
so a planar pose (x, y, theta) places it directly. Collision is an upright cylinder (the
agent's disc); the visual model is a compound of primitives with per-part colours.

- Pursuer: a TurtleBot 2 look-alike (Kobuki base, three plates on posts, a Kinect-like
  sensor bar on top, behind the camera's optical centre so it never enters the image).
- Evader: the articulated person of :mod:`pegame_pybullet.person` (its colours are here);
  1.70 m tall (the oracle detector's default ``evader_height``), red shirt, blue trousers.
  The scenery is neutral grey, so the clothing is the only saturated colour in view (what
  ``detector=vision``'s colour model relies on).
"""

from __future__ import annotations

from dataclasses import dataclass

import pybullet

from pegame_pybullet.client import Client

SHIRT_RGB = (0.80, 0.12, 0.10)
TROUSERS_RGB = (0.12, 0.22, 0.65)
SKIN_RGB = (0.87, 0.68, 0.55)
EVADER_HEIGHT = 1.70  # m
PURSUER_HEIGHT = 0.42  # m, to the top of the sensor bar


@dataclass(frozen=True)
class Part:
    """One primitive of a visual model: shape (pybullet GEOM_*), size, position (m, body
    frame) and colour. size: radius for spheres; (radius, length) for capsules and
    cylinders; half extents (x, y, z) for boxes."""

    shape: int
    size: tuple[float, ...]
    position: tuple[float, float, float]
    rgb: tuple[float, float, float]


def turtlebot(radius: float, camera_height: float) -> list[Part]:
    """A TurtleBot 2 of base ``radius`` (m) with its camera's optical centre at height
    ``camera_height`` (m) above the base's centre."""
    cyl, box = pybullet.GEOM_CYLINDER, pybullet.GEOM_BOX
    dark, grey, black = (0.15, 0.15, 0.15), (0.55, 0.55, 0.55), (0.05, 0.05, 0.05)
    plate_top = min(0.37, camera_height - 0.03)
    parts = [Part(cyl, (radius, 0.09), (0.0, 0.0, 0.055), dark)]
    for z, colour in ((0.13, grey), (0.5 * (0.13 + plate_top), grey), (plate_top, dark)):
        parts.append(Part(cyl, (0.9 * radius, 0.01), (0.0, 0.0, z), colour))
    post = 0.6 * radius
    for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        length = plate_top - 0.1
        parts.append(Part(cyl, (0.006, length), (sx * post, sy * post, 0.1 + 0.5 * length), grey))
    parts.append(Part(box, (0.03, 0.14, 0.02), (-0.035, 0.0, camera_height), black))
    return parts


def create_body(client: Client, parts: list[Part], collision_radius: float, height: float) -> int:
    """A static body: visual ``parts`` and an upright collision cylinder of
    ``collision_radius`` (m) and ``height`` (m) standing on the body's origin."""
    radii, lengths, halves = [], [], []
    for part in parts:
        radii.append(part.size[0] if part.shape != pybullet.GEOM_BOX else 0.0)
        lengths.append(
            part.size[1] if part.shape in (pybullet.GEOM_CAPSULE, pybullet.GEOM_CYLINDER) else 0.0
        )
        halves.append(list(part.size) if part.shape == pybullet.GEOM_BOX else [0.0, 0.0, 0.0])
    visual = client.createVisualShapeArray(
        [part.shape for part in parts],
        radii=radii,
        lengths=lengths,
        halfExtents=halves,
        visualFramePositions=[list(part.position) for part in parts],
        rgbaColors=[[*part.rgb, 1.0] for part in parts],
    )
    collision = client.createCollisionShape(
        pybullet.GEOM_CYLINDER,
        radius=collision_radius,
        height=height,
        collisionFramePosition=[0.0, 0.0, 0.5 * height],
    )
    return client.createMultiBody(0, collision, visual)
