"""``sim=pybullet``: the game in a 3D PyBullet world with a rendered RGB-D camera.

The world (:mod:`pegame_pybullet.world`) is the occupancy grid extruded into walls on a
floor; the agents (:mod:`pegame_pybullet.bodies`) are a TurtleBot-like pursuer and a
human-shaped evader, the paper's Gazebo setup (Sec. "Simulation based validation").

Motion. Both agents are kinematic unicycles, as in the grid simulator: a command (v, w)
is saturated to the agent's limits and integrated exactly over dt
(:func:`pegame.sims.grid.unicycle`); the move's chord is then checked with PyBullet
collision queries (``getClosestPoints`` of the agent's cylinder against the wall boxes
the broadphase finds near it) in sub-steps no longer than the cylinder's radius, so it
cannot tunnel through a wall, and a blocked sub-step is bisected to the last free point:
the agent stops at the wall and may still turn. A kinematic body is exact and
deterministic where a dynamic one driven by velocity would bounce, slide and depend on
solver settings. The collision cylinder is ``collision_inset`` grid cells thinner than
the body radius (half a cell by default): the planners and the grid simulator keep an
agent's *cell centre* a radius away from blocked *cell centres*, which lets its disc reach
into a wall's box at convex corners; with the inset every cell centre they consider free
(their paths run through them) is free here too. The agents do not collide with each
other (as in the grid simulator).

Camera. Rendered with TinyRenderer (:mod:`pegame_pybullet.camera`) at ``camera_hz``:
:meth:`PybulletSimulator.sense_1v1` renders when a frame is due and otherwise returns the last
frame again (same object, its own time and poses). The optical centre is on the pursuer's
axis, so ``SensorFrame.camera_pose`` is the pursuer's pose as in the grid simulator; the
pursuer's own body is moved out of the way while its camera renders, and the floor is
composited in closed form (see :mod:`pegame_pybullet.camera`). The frame carries
the intrinsics, the optical-to-map transform and the segmentation labels ``evader``,
``pursuer`` and ``floor`` (every other body is a wall box).

Resources. The physics server is connected at the first :meth:`reset` and disconnected in
:meth:`close`, which the game calls once per game, so many games in one process keep
memory flat.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet

from pegame.api import Context, OneOnOneSimulator
from pegame.errors import ConfigError, require
from pegame.sims.grid import saturate, unicycle
from pegame.types import Body, Pose, SensorFrame, Velocity
from pegame_pybullet.bodies import EVADER_HEIGHT, PURSUER_HEIGHT, create_body, turtlebot
from pegame_pybullet.camera import DepthCamera
from pegame_pybullet.client import Client
from pegame_pybullet.person import Walker, create_person
from pegame_pybullet.world import build_world

PENETRATION_TOLERANCE = 1e-4  # m; a touching pose (distance ~0 after bisection) is free
BISECTIONS = 8  # a blocked sub-step is resolved to 1/256 of its length
HIDDEN_Z = -1000.0  # m; where a body goes while a camera must not see it
#: rad, the camera's downward pitch in the paper's simulations (Sec. V: "a RGB-D sensor
#: tilted at an angle of pi/8 downward")
PAPER_TILT = math.pi / 8


def _orientation(theta: float) -> list[float]:
    return [0.0, 0.0, math.sin(0.5 * theta), math.cos(0.5 * theta)]


class _Mover:
    """One agent's body moved as a kinematic unicycle and stopped by the walls."""

    def __init__(
        self,
        client: Client,
        body: int,
        walls: tuple[int, ...],
        limits: Body,
        collision_radius: float,
        height: float,
        walker: Walker | None = None,
    ) -> None:
        self.client, self.body, self.walls, self.limits = client, body, frozenset(walls), limits
        self.radius, self.height = collision_radius, height
        self.walker = walker  # the evader's gait, advanced by the distance each move covers
        self.pose = Pose(0.0, 0.0, 0.0)

    def _place(self, x: float, y: float, theta: float) -> None:
        self.client.resetBasePositionAndOrientation(self.body, [x, y, 0.0], _orientation(theta))

    def collides(self, x: float, y: float, theta: float = 0.0) -> bool:
        """True when the body at (x, y) (m, map frame) penetrates a wall; leaves it there."""
        self._place(x, y, theta)
        r = self.radius
        # The broadphase names the few wall boxes near (x, y); only those are tested exactly.
        near = (
            self.client.getOverlappingObjects([x - r, y - r, 0.0], [x + r, y + r, self.height])
            or ()
        )
        for body, _ in near:
            if body in self.walls:
                points = self.client.getClosestPoints(self.body, body, 0.0)
                if any(point[8] < -PENETRATION_TOLERANCE for point in points):
                    return True
        return False

    def hide(self) -> None:
        """Move the body out of every camera's view until :meth:`show`."""
        self.client.resetBasePositionAndOrientation(
            self.body, [self.pose.x, self.pose.y, HIDDEN_Z], [0.0, 0.0, 0.0, 1.0]
        )

    def show(self) -> None:
        self._place(self.pose.x, self.pose.y, self.pose.theta)

    def reset(self, pose: Pose) -> bool:
        """Place the body at ``pose``; False when it is inside a wall there."""
        self.pose = pose
        if self.walker is not None:
            self.walker.reset()
        return not self.collides(pose.x, pose.y, pose.theta)

    def move(self, cmd: Velocity, dt: float) -> None:
        start = self.pose
        target = unicycle(start, saturate(cmd, self.limits), dt)
        dx, dy = target.x - start.x, target.y - start.y
        steps = max(1, math.ceil(math.hypot(dx, dy) / self.radius))
        free = 0.0  # fraction of the chord known to be free
        for k in range(1, steps + 1):
            fraction = k / steps
            if self.collides(start.x + fraction * dx, start.y + fraction * dy):
                low, high = free, fraction
                for _ in range(BISECTIONS):
                    mid = 0.5 * (low + high)
                    if self.collides(start.x + mid * dx, start.y + mid * dy):
                        high = mid
                    else:
                        low = mid
                free = low
                break
            free = fraction
        self.pose = Pose(start.x + free * dx, start.y + free * dy, target.theta)
        self._place(self.pose.x, self.pose.y, self.pose.theta)
        if self.walker is not None:  # the distance walked along the new heading (m)
            c, s = math.cos(target.theta), math.sin(target.theta)
            self.walker.walk(free * (c * dx + s * dy))


class PybulletSimulator(OneOnOneSimulator):
    """Kinematic unicycles in a 3D PyBullet world; an RGB-D camera with segmentation."""

    description = "3D PyBullet world from the map: TurtleBot, human evader, rendered RGB-D camera."

    @dataclass
    class Config:
        width: int = 320  # px, image width: half the TurtleBot camera's 640, for speed (README)
        height: int = 240  # px, image height: half the TurtleBot camera's 480
        camera_hz: float = 10.0  # Hz; a frame is rendered when due, the last one reused otherwise
        camera_height: float = 0.4  # m, optical centre above the floor
        camera_tilt: float = PAPER_TILT  # rad, downward pitch (0: level)
        wall_height: float = 2.0  # m, height of the extruded walls
        collision_inset: float = (
            0.5  # grid cells by which collision cylinders are thinner than the bodies
        )
        gui: bool = False  # open the PyBullet GUI (needs a display) instead of the headless server

        def __post_init__(self) -> None:
            for key in ("width", "height"):
                value = getattr(self, key)
                require(value >= 8, key, "a whole number of pixels >= 8", value)
            require(self.camera_hz > 0, "camera_hz", "a positive rate in Hz", self.camera_hz)
            require(self.wall_height > 0, "wall_height", "a positive height in m", self.wall_height)
            require(
                0 < self.camera_height < self.wall_height,
                "camera_height",
                f"a height in m in (0, sim.wall_height = {self.wall_height})",
                self.camera_height,
            )
            tilt, inset = self.camera_tilt, self.collision_inset
            require(abs(tilt) < 0.5 * math.pi, "camera_tilt", "(-pi/2, pi/2) rad", tilt)
            require(inset >= 0, "collision_inset", "a number of cells >= 0", inset)

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        inset = config.collision_inset * context.grid.resolution
        for role, body in (("pursuer", context.pursuer), ("evader", context.evader)):
            if body.radius - inset <= 0:
                raise ConfigError(
                    f"Invalid value for 'sim.collision_inset': {config.collision_inset!r}. Allowed: fewer "
                    f"cells than the {role} radius ({body.radius} m) at {context.grid.resolution} m per cell."
                )
            for key in ("a_max", "alpha_max"):
                if math.isfinite(getattr(body, key)):
                    raise ConfigError(
                        f"Invalid value for '{role}.{key}': {getattr(body, key)!r}. The pybullet "
                        f"simulator has no acceleration limits: leave {role}.{key} at .inf, or "
                        "use the grid simulator (sim=grid)."
                    )
        self._inset = inset
        self._client: Client | None = None
        self._frame: SensorFrame | None = None

    # ------------------------------------------------------------------ world

    @property
    def client(self) -> Client:
        """The connection to the physics server (made by the first reset or place)."""
        if self._client is None:
            raise RuntimeError("The pybullet simulator is not connected: reset it first.")
        return self._client

    def _connect(self) -> None:
        ctx, cfg = self.context, self.config
        client = self._client = Client(gui=cfg.gui)
        self.world = build_world(client, ctx.grid, cfg.wall_height)
        walls = self.world.walls
        radius = ctx.pursuer.radius - self._inset
        robot = turtlebot(ctx.pursuer.radius, cfg.camera_height)
        pursuer = create_body(client, robot, radius, PURSUER_HEIGHT)
        self._pursuer = _Mover(client, pursuer, walls, ctx.pursuer, radius, PURSUER_HEIGHT)
        radius = ctx.evader.radius - self._inset
        evader = create_person(client, radius, EVADER_HEIGHT)
        walker = Walker(client, evader)
        self._evader = _Mover(client, evader, walls, ctx.evader, radius, EVADER_HEIGHT, walker)
        self.labels = {"evader": evader, "pursuer": pursuer, "floor": self.world.floor}
        self.camera = DepthCamera(
            client,
            cfg.width,
            cfg.height,
            ctx.camera.fov,
            ctx.camera.near,
            ctx.camera.far,
            cfg.camera_height,
            cfg.camera_tilt,
        )
        if cfg.gui:
            self._frame_gui()

    def _frame_gui(self) -> None:
        """Point the GUI's camera down at the middle of the map."""
        x0, x1, y0, y1 = self.context.grid.extent
        self.client.configureDebugVisualizer(pybullet.COV_ENABLE_GUI, 0)
        self.client.resetDebugVisualizerCamera(
            max(x1 - x0, y1 - y0), 0.0, -89.0, [0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0]
        )

    # ------------------------------------------------------------- Simulator

    def reset_1v1(self, pursuer: Pose, evader: Pose) -> None:
        for role, free in zip(("pursuer", "evader"), self.place(pursuer, evader)):
            if not free:
                pose = pursuer if role == "pursuer" else evader
                raise ValueError(
                    f"{role} start pose {pose} is inside a wall for radius "
                    f"{getattr(self.context, role).radius} m"
                )

    def place(self, pursuer: Pose, evader: Pose) -> tuple[bool, bool]:
        """Put both agents at the given poses (connecting first if needed) and forget the
        last frame; returns whether each pose is free of the walls. :meth:`reset_1v1` is this
        plus the check; replaying another simulator's trajectory uses it directly."""
        if self._client is None or not self._client.connected:
            self._connect()
        self._frame = None
        return self._pursuer.reset(pursuer), self._evader.reset(evader)

    def step_1v1(self, pursuer_cmd: Velocity, evader_cmd: Velocity, dt: float) -> None:
        self._pursuer.move(pursuer_cmd, dt)
        self._evader.move(evader_cmd, dt)

    @property
    def poses_1v1(self) -> tuple[Pose, Pose]:
        return self._pursuer.pose, self._evader.pose

    def sense_1v1(self, time: float) -> SensorFrame:
        period = 1.0 / self.config.camera_hz
        if self._frame is None or time >= self._frame.time + period - 1e-9:
            pose = self._pursuer.pose
            transform = self.camera.camera_to_map(pose)
            rgb, depth, seg = self._render(transform)
            self._frame = SensorFrame(
                time=time,
                camera_pose=pose,
                evader_truth=self._evader.pose,
                rgb=rgb,
                depth=depth,
                segmentation=seg,
                intrinsics=self.camera.intrinsics,
                camera_to_map=transform,
                labels=self.labels,
            )
        return self._frame

    def _render(self, transform: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The camera's images, with the pursuer's body and the floor body out of the way:
        TinyRenderer does not clip at the near plane, so the robot would see its own plates,
        and the camera composites the floor in closed form, faster than rasterising it (in
        the GUI the floor body stays put, for the viewer, and gives the same image)."""
        floor = self.world.floor
        placed = self.client.getBasePositionAndOrientation(floor)
        self._pursuer.hide()
        if not self.config.gui:
            self.client.resetBasePositionAndOrientation(floor, [0.0, 0.0, HIDDEN_Z], placed[1])
        try:
            return self.camera.render(transform, floor)
        finally:
            self._pursuer.show()
            if not self.config.gui:
                self.client.resetBasePositionAndOrientation(floor, *placed)

    def close(self) -> None:
        if self._client is not None:
            self._client.disconnect()
        self._client = None
        self._frame = None

    # ------------------------------------------------------------ evaluation

    def evader_visible_fraction(self, scale: int = 3) -> float:
        """Fraction of the evader visible in the last frame: its pixels there over its pixels
        when rendered alone (walls, floor and pursuer removed) by the same camera on a canvas
        ``scale`` times wider and taller (same focal length), so that neither occlusion nor
        the image border cuts it. For evaluating detectors, right after :meth:`sense`
        rendered the frame (the agents must not have moved since); costs a large render."""
        frame = self._frame
        if frame is None:
            raise RuntimeError("no frame yet: call sense() first")
        evader = self.labels["evader"]
        seen = int(np.count_nonzero(frame.segmentation == evader))
        if seen == 0:
            return 0.0
        camera = self.context.camera
        wide = DepthCamera(
            self.client,
            scale * self.config.width,
            scale * self.config.height,
            2.0 * math.atan(scale * math.tan(0.5 * camera.fov)),
            camera.near,
            camera.far,
            self.config.camera_height,
            self.config.camera_tilt,
        )
        others = [*self.world.walls, self.world.floor, self.labels["pursuer"]]
        placed = [self.client.getBasePositionAndOrientation(body) for body in others]
        for body, (position, orientation) in zip(others, placed):
            self.client.resetBasePositionAndOrientation(
                body, [*position[:2], HIDDEN_Z], orientation
            )
        try:
            transform = frame.camera_to_map
            assert transform is not None  # this simulator's frames carry it
            _, _, alone = wide.render(transform, self.world.floor)
        finally:
            for body, (position, orientation) in zip(others, placed):
                self.client.resetBasePositionAndOrientation(body, position, orientation)
        whole = int(np.count_nonzero(alone == evader))
        return min(1.0, seen / whole) if whole else 0.0
