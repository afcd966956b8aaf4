"""The evader as an articulated person 1.70 m tall, walking with a gait while it moves.

A PyBullet multibody built from primitives: the base is the pelvis frame on the floor under
the person's centre (x forward, z up) and carries the torso, neck and head and the upright
collision cylinder of the agent's disc; eight links hang from it on revolute joints about
the body's lateral axis: thighs on the hips, shins on the knees, upper arms on the
shoulders, forearms (with the hands) on the elbows. The links have no collision shapes, so
collision queries against the walls see only the cylinder. Red shirt and sleeves, blue
trousers, skin on the forearms, hands, neck and head: the colours ``detector=vision``'s
colour model looks for, so it works on this body as on the rigid one it replaces.

pybullet_data's ``humanoid/humanoid.urdf`` (the DeepMimic character) was not used: it is
modelled y-up at four times a person's size (``globalScaling=0.25`` brings it to ~1.6 m),
has spherical joints, is white, and its URDF prints eight warnings on every load.

Gait: a phase advances with the distance walked along the heading (m), one cycle per
``STRIDE`` (two steps), so the legs move exactly as fast as the body does and stop when it
stops; walking backwards runs the cycle backwards. Per leg, with its phase psi (the right
leg half a cycle behind the left): hip flexion ``HIP_SWING`` sin psi, knee flexion
``KNEE_FLEX`` max(0, cos psi) (the knee bends while the leg swings forward), shoulder
flexion -``ARM_SWING`` sin psi (each arm swings against its leg), elbow flexion
``ELBOW_FLEX``. A sinusoidal simplification of normal walking's sagittal joint angles
(Winter, *Biomechanics and Motor Control of Human Movement*, 2009: hip about +-20 degrees,
knee up to ~60 degrees in swing).
"""

from __future__ import annotations

import math

import pybullet

from pegame_pybullet.bodies import SHIRT_RGB, SKIN_RGB, TROUSERS_RGB, Part
from pegame_pybullet.client import Client

HIP_HEIGHT = 0.86  # m above the floor
SHOULDER_HEIGHT = 1.41  # m above the floor
THIGH, SHIN = 0.43, 0.43  # m, hip to knee and knee to sole
UPPER_ARM, FOREARM = 0.29, 0.27  # m, shoulder to elbow and elbow to wrist
STRIDE = 1.4  # m walked per gait cycle (two steps of 0.7 m)
HIP_SWING = 0.35  # rad, amplitude of hip flexion
KNEE_FLEX = 1.0  # rad, peak knee flexion in swing
ARM_SWING = 0.3  # rad, amplitude of shoulder flexion
ELBOW_FLEX = 0.3  # rad, constant elbow flexion

# Joint axes: a positive angle about (0, -1, 0) swings a limb hanging down forward (+x).
FLEX_FORWARD = (0.0, -1.0, 0.0)
FLEX_BACKWARD = (0.0, 1.0, 0.0)  # the knee bends the shin backwards
#: joint names in link order (two per side: left first, then right)
JOINTS = (
    "left_hip",
    "left_knee",
    "right_hip",
    "right_knee",
    "left_shoulder",
    "left_elbow",
    "right_shoulder",
    "right_elbow",
)


def _capsule(radius: float, top: float, bottom: float, rgb: tuple[float, float, float]) -> Part:
    """A capsule along z from ``top`` to ``bottom`` (m, link frame, outer ends)."""
    length = top - bottom - 2.0 * radius
    return Part(pybullet.GEOM_CAPSULE, (radius, length), (0.0, 0.0, 0.5 * (top + bottom)), rgb)


def trunk() -> list[Part]:
    """The base's visual parts: torso, neck and head (m, base frame, floor at z = 0)."""
    box, sph, cyl = pybullet.GEOM_BOX, pybullet.GEOM_SPHERE, pybullet.GEOM_CYLINDER
    return [
        Part(box, (0.11, 0.17, 0.30), (0.0, 0.0, 1.15), SHIRT_RGB),
        Part(box, (0.10, 0.15, 0.06), (0.0, 0.0, HIP_HEIGHT - 0.01), TROUSERS_RGB),  # hips
        Part(cyl, (0.05, 0.08), (0.0, 0.0, 1.48), SKIN_RGB),
        Part(sph, (0.11,), (0.0, 0.0, 1.59), SKIN_RGB),
    ]


#: a link: parent index, joint position (m, parent frame), joint axis, visual parts
Link = tuple[int, tuple[float, float, float], tuple[float, float, float], list[Part]]


def limbs() -> list[Link]:
    """The eight links as (parent link index, joint position in the parent's frame (m),
    joint axis, visual parts in the link's frame); the joint is the link frame's origin.
    Parent 0 is the base; link i (0-based) is parent i + 1 of the next."""
    links: list[Link] = []
    for side in (1.0, -1.0):  # left (+y), right
        thigh = len(links) + 1
        links.append(
            (
                0,
                (0.0, side * 0.095, HIP_HEIGHT),
                FLEX_FORWARD,
                [_capsule(0.075, 0.06, -THIGH, TROUSERS_RGB)],
            )
        )
        links.append(
            (thigh, (0.0, 0.0, -THIGH), FLEX_BACKWARD, [_capsule(0.065, 0.04, -SHIN, TROUSERS_RGB)])
        )
    for side in (1.0, -1.0):
        upper = len(links) + 1
        links.append(
            (
                0,
                (0.0, side * 0.215, SHOULDER_HEIGHT),
                FLEX_FORWARD,
                [_capsule(0.045, 0.04, -UPPER_ARM, SHIRT_RGB)],
            )
        )
        hand = Part(pybullet.GEOM_SPHERE, (0.045,), (0.0, 0.0, -FOREARM - 0.03), SKIN_RGB)
        links.append(
            (
                upper,
                (0.0, 0.0, -UPPER_ARM),
                FLEX_FORWARD,
                [_capsule(0.037, 0.03, -FOREARM, SKIN_RGB), hand],
            )
        )
    return links


def _visual(client: Client, parts: list[Part]) -> int:
    """A visual shape array of ``parts``."""
    radii = [part.size[0] if part.shape != pybullet.GEOM_BOX else 0.0 for part in parts]
    lengths = [
        part.size[1] if part.shape in (pybullet.GEOM_CAPSULE, pybullet.GEOM_CYLINDER) else 0.0
        for part in parts
    ]
    halves = [list(part.size) if part.shape == pybullet.GEOM_BOX else [0.0] * 3 for part in parts]
    return client.createVisualShapeArray(
        [part.shape for part in parts],
        radii=radii,
        lengths=lengths,
        halfExtents=halves,
        visualFramePositions=[list(part.position) for part in parts],
        rgbaColors=[[*part.rgb, 1.0] for part in parts],
    )


def create_person(client: Client, collision_radius: float, height: float) -> int:
    """The person as a static multibody (mass 0: moved kinematically) with an upright
    collision cylinder of ``collision_radius`` (m) and ``height`` (m) on the base."""
    collision = client.createCollisionShape(
        pybullet.GEOM_CYLINDER,
        radius=collision_radius,
        height=height,
        collisionFramePosition=[0.0, 0.0, 0.5 * height],
    )
    links = limbs()
    count = len(links)
    return client.createMultiBody(
        0,
        collision,
        _visual(client, trunk()),
        linkMasses=[0.0] * count,
        linkCollisionShapeIndices=[-1] * count,
        linkVisualShapeIndices=[_visual(client, parts) for _, _, _, parts in links],
        linkPositions=[list(position) for _, position, _, _ in links],
        linkOrientations=[[0.0, 0.0, 0.0, 1.0]] * count,
        linkInertialFramePositions=[[0.0, 0.0, 0.0]] * count,
        linkInertialFrameOrientations=[[0.0, 0.0, 0.0, 1.0]] * count,
        linkParentIndices=[parent for parent, _, _, _ in links],
        linkJointTypes=[pybullet.JOINT_REVOLUTE] * count,
        linkJointAxis=[list(axis) for _, _, axis, _ in links],
    )


def gait_angles(distance: float) -> tuple[float, ...]:
    """Joint angles (rad, in :data:`JOINTS` order) after walking ``distance`` m."""
    phase = 2.0 * math.pi * distance / STRIDE
    legs, arms = [], []
    for psi in (phase, phase + math.pi):  # left, right
        legs += [HIP_SWING * math.sin(psi), KNEE_FLEX * max(0.0, math.cos(psi))]
        arms += [-ARM_SWING * math.sin(psi), ELBOW_FLEX]
    return (*legs, *arms)


class Walker:
    """Drives a person's joints from the distance it has walked (see the module docstring)."""

    def __init__(self, client: Client, body: int) -> None:
        self.client, self.body = client, body
        self.distance = 0.0  # m walked along the heading since reset

    def reset(self) -> None:
        self.distance = 0.0
        self._pose()

    def walk(self, distance: float) -> None:
        """Advance by ``distance`` m along the heading (negative: backwards)."""
        self.distance += distance
        self._pose()

    def _pose(self) -> None:
        for joint, angle in enumerate(gait_angles(self.distance)):
            self.client.resetJointState(self.body, joint, angle)
