"""A game from a composed config: its scenario, its plugins, its play and its result
(paper, Sec. "Simulation based validation").

Protocol: both agents spawn at random free poses (seeded) with the evader in the
pursuer's view; the game lasts ``game.t_max`` seconds of control ticks played by
:class:`pegame.loop.TickLoop` (the order of a tick is written there, once). The pursuer
learns about the evader only through its detector; the evader is told the pursuer's pose.

A :class:`Scenario` is the config validated once: the map, the bodies, the camera, the
plugin classes and their configs. ``scenario.game(seed)`` builds one :class:`Game`: every
component gets its own generator from the master seed (one SeedSequence stream per
component, in :data:`STREAMS` order), so the same scenario and seed give the same game.

Teams (``team.pursuers``, ``team.evaders``): member 0 of each role, detector pair (0, 0)
and evader 0's estimator get the 1v1 game's generators; every other member draws from a
stream spawned after them (:meth:`Game._member`), and the spawn places the 1v1
game's pair first (:func:`spawn_team`), so a 1v1 game is the special case, unchanged.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import math
from dataclasses import dataclass, fields
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig

from pegame import registry
from pegame.api import (
    INTERFACES,
    Context,
    Detector,
    Estimator,
    Evader,
    Plugin,
    Pursuer,
    Recorder,
    Simulator,
    Tick,
)
from pegame.config import (
    EnvConfig,
    GameConfig,
    TeamConfig,
    plain,
    resolve_map_path,
    team_members,
    typed,
)
from pegame.errors import ConfigError, SpawnError
from pegame.files import write_atomic
from pegame.grid import OccupancyGrid, load_map, per_grid, read_only
from pegame.kernel_cache import watch_compilation
from pegame.loop import GamePlugins, TickLoop, check_team
from pegame.metrics import TeamMetrics, TrackingMetrics
from pegame.navigation import Planner
from pegame.types import Body, Camera, Pose
from pegame.visibility import in_view, visibility_region

log = logging.getLogger(__name__)

#: the order in which components draw their generators from the master seed: the spawn,
#: then the plugin kinds in api.INTERFACES order (append only: games depend on it)
STREAMS = ("spawn", *INTERFACES)


def cached_map(path: Path) -> OccupancyGrid:
    """The map at ``path``, loaded once per process while the file is unchanged: grids
    are immutable, so the games of a job share one (and the planners cached on it)."""
    try:
        stamp = path.stat().st_mtime_ns
    except OSError:
        return load_map(path)  # raises the MapError that names the missing file
    return _load_map_once(str(path), stamp)


@lru_cache(maxsize=8)
def _load_map_once(path: str, stamp: int) -> OccupancyGrid:
    return load_map(path)


#: the paper's letters for its agents; other strategies appear by name in pairings
PAPER_LETTERS = {"random": "R", "smart": "S"}


def pairing(pursuer: str, evader: str) -> str:
    """The paper's pairing label, e.g. 'S-R' for a smart pursuer and a random evader
    ('policy-S' for a pursuer named policy)."""
    return f"{PAPER_LETTERS.get(pursuer, pursuer)}-{PAPER_LETTERS.get(evader, evader)}"


def spawn(context: Context, rng: np.random.Generator, attempts: int = 500) -> tuple[Pose, Pose]:
    """Random start poses: the pursuer on a free cell it can move from, the evader on a
    free cell in the pursuer's view (FOV, range, line of sight) that the pursuer can reach,
    the two bodies apart (centres at least the sum of their radii from each other).

    An evader cell that would overlap the pursuer is passed over for the next one drawn,
    so only the seeds whose first choice overlapped start elsewhere.
    Raises SpawnError when ``attempts`` pursuer draws give no valid pair.
    """
    grid, camera = context.grid, context.camera
    apart = context.pursuer.radius + context.evader.radius
    evader_space = Planner.shared(grid, context.evader.radius).traversable
    rows, cols = traversable_cells(grid, context.pursuer.radius)
    for _ in range(attempts if rows.size else 0):
        k = int(rng.integers(rows.size))
        x, y = grid.cell_to_world(rows[k], cols[k])
        pursuer = Pose(x, y, float(rng.uniform(-math.pi, math.pi)))
        er, ec = np.nonzero(visibility_region(grid, pursuer, camera) & evader_space)
        order = rng.permutation(er.size)
        for j in order[:20]:
            ex, ey = grid.cell_to_world(er[j], ec[j])
            if math.hypot(ex - x, ey - y) >= apart and in_view(grid, camera, pursuer, (ex, ey)):
                return pursuer, Pose(ex, ey, float(rng.uniform(-math.pi, math.pi)))
    raise SpawnError(
        f"No valid spawn on map '{grid.name}': after {attempts} tries there is no free pose for "
        f"the pursuer (radius {context.pursuer.radius} m) with a free cell for the evader (radius "
        f"{context.evader.radius} m) in its view (range {camera.near}-{camera.far} m, FOV "
        f"{camera.fov:.3f} rad). Use a map with more free space, smaller radii or a longer camera range."
    )


def traversable_cells(grid: OccupancyGrid, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) of the cells where a body of ``radius`` m can stand (the shared
    planner's traversable mask), row-major; computed once per grid and radius."""

    def build(grid: OccupancyGrid) -> tuple[np.ndarray, np.ndarray]:
        rows, cols = np.nonzero(Planner.shared(grid, radius).traversable)
        return read_only(rows), read_only(cols)

    return per_grid(grid, ("game", "traversable cells", radius), build)


def _apart(x: float, y: float, radius: float, placed: list[tuple[Pose, float]]) -> bool:
    """Whether a body of ``radius`` (m) at (x, y) overlaps none of the ``placed`` (pose,
    radius) bodies."""
    return all(math.hypot(x - p.x, y - p.y) >= radius + r for p, r in placed)


def member_stream(seed: int, kind: str, *index: int) -> np.random.SeedSequence:
    """The seed sequence of a team's extra member of ``kind`` at ``index`` (a member
    number, or a detector pair (i, j)) in the game with master seed ``seed``: a stream
    after every 1v1 stream (spawn key ``len(STREAMS)``), so member 0 keeps the 1v1 game's."""
    return np.random.SeedSequence(seed, spawn_key=(len(STREAMS), STREAMS.index(kind), *index))


def spawn_team(
    context: Context, rng: np.random.Generator, pursuers: int, evaders: int, attempts: int = 200
) -> tuple[tuple[Pose, ...], tuple[Pose, ...]]:
    """Start poses of N ``pursuers`` and M ``evaders``: pursuer 0 and evader 0 as
    :func:`spawn` draws them (a 1v1 game's start, so games of every team size on one
    seed share it), then the other pursuers on free cells they can move from, then the
    other evaders on free cells in the view of at least one pursuer; no two bodies
    overlap (centres at least the sum of their radii apart). The extra members draw from
    ``rng`` after the first pair; when they find no room the whole team is drawn again.

    Raises SpawnError naming the map and the team when ``attempts`` draws give none.
    """
    first = spawn(context, rng)
    if pursuers == 1 and evaders == 1:
        return (first[0],), (first[1],)
    grid, camera = context.grid, context.camera
    rp, re = context.pursuer.radius, context.evader.radius
    pursuer_cells = np.column_stack(traversable_cells(grid, rp))
    evader_space = Planner.shared(grid, re).traversable
    for _ in range(attempts):
        placed = [(first[0], rp), (first[1], re)]
        team_p, team_e = [first[0]], [first[1]]
        for _member in range(pursuers - 1):
            for k in rng.integers(len(pursuer_cells), size=50):
                x, y = grid.cell_to_world(*pursuer_cells[k])
                if _apart(x, y, rp, placed):
                    pose = Pose(x, y, float(rng.uniform(-math.pi, math.pi)))
                    team_p.append(pose)
                    placed.append((pose, rp))
                    break
        seen = np.zeros(grid.blocked.shape, dtype=bool)
        for pose in team_p:
            seen |= visibility_region(grid, pose, camera)
        er, ec = np.nonzero(seen & evader_space)
        for _member in range(evaders - 1):
            for j in rng.permutation(er.size)[:50]:
                x, y = grid.cell_to_world(er[j], ec[j])
                watched = any(in_view(grid, camera, p, (x, y)) for p in team_p)
                if watched and _apart(x, y, re, placed):
                    pose = Pose(x, y, float(rng.uniform(-math.pi, math.pi)))
                    team_e.append(pose)
                    placed.append((pose, re))
                    break
        if len(team_p) == pursuers and len(team_e) == evaders:
            return tuple(team_p), tuple(team_e)
        first = spawn(context, rng)
    raise SpawnError(
        f"No valid spawn on map '{grid.name}' for a team of {pursuers} pursuer(s) (radius "
        f"{rp} m) and {evaders} evader(s) (radius {re} m): after {attempts} tries there is no "
        "room for every body apart with each evader in some pursuer's view. Use a map with "
        "more free space, a smaller team (team.pursuers, team.evaders) or smaller radii."
    )


@dataclass
class Outcome:
    """A played game: its result (JSON-ready, no wall-clock values), trajectory rows and
    their column names."""

    result: dict[str, Any]
    trajectory: list[tuple]
    header: tuple[str, ...] = ()


TRAJECTORY_HEADER = (
    "step",
    "time",
    "pursuer_x",
    "pursuer_y",
    "pursuer_theta",
    "evader_x",
    "evader_y",
    "evader_theta",
    "detected",
    "in_view",
)


def team_header(pursuers: int, evaders: int) -> tuple[str, ...]:
    """The trajectory columns of a team game: step, time, every pursuer's pose
    (``pursuer_<i>_x`` ...), every evader's, then per evader whether some pursuer
    detected it (``detected_<j>``) and had it in view (``in_view_<j>``)."""
    poses = [
        f"{role}_{k}_{axis}"
        for role, count in (("pursuer", pursuers), ("evader", evaders))
        for k in range(count)
        for axis in ("x", "y", "theta")
    ]
    flags = [f"{flag}_{j}" for j in range(evaders) for flag in ("detected", "in_view")]
    return ("step", "time", *poses, *flags)


def trajectory_row(t: Tick) -> tuple:
    """A tick as a row of :func:`team_header` (a 1v1 game's as a row of
    :data:`TRAJECTORY_HEADER`, the same columns under their 1v1 names). (Loops, not
    comprehensions: this runs every tick.)"""
    row: list = [t.step, round(t.time, 6)]
    for pose in t.pursuers:
        row += (pose.x, pose.y, pose.theta)
    for pose in t.evaders:
        row += (pose.x, pose.y, pose.theta)
    detections, in_views = t.detections, t.in_views
    for j in range(len(t.evaders)):
        detected = seen = 0
        for i in range(len(detections)):
            detected |= detections[i][j] is not None
            seen |= in_views[i][j]
        row += (int(detected), int(seen))
    return tuple(row)


def check_room_for_team(context: Context, pursuers: int, evaders: int) -> None:
    """SpawnError naming the map and the team when the map cannot hold the team's bodies
    apart: fewer traversable cells on a lattice of spacing twice the largest radius (the
    centres of bodies that cannot overlap) than there are members."""
    grid = context.grid
    radius = max(context.pursuer.radius, context.evader.radius)
    step = max(1, math.ceil(2 * radius / grid.resolution))
    room = 0
    for body in (context.pursuer, context.evader):
        space = Planner.shared(grid, body.radius).traversable
        room = max(room, int(np.count_nonzero(space[::step, ::step])))
    if room < pursuers + evaders:
        raise SpawnError(
            f"No valid spawn on map '{grid.name}' for a team of {pursuers} pursuer(s) and "
            f"{evaders} evader(s): it has room for {room} bodies of radius {radius} m apart. "
            "Use a smaller team (team.pursuers, team.evaders), a larger map or smaller radii."
        )


class Scenario:
    """A composed config validated once: settings, camera, map, plugin classes and their
    configs, and the game context. Every bad value or name raises a PegameError here,
    before any game is played. ``base_dir``: where relative map paths are found."""

    def __init__(self, cfg: DictConfig, base_dir: str | Path | None = None) -> None:
        watch_compilation()  # before any game's kernels compile: say so on a cold cache
        self.settings: GameConfig = typed(cfg.game, GameConfig, "game")
        camera: Camera = typed(cfg.camera, Camera, "camera")
        env: EnvConfig = typed(cfg.env, EnvConfig, "env")
        self.env_name = env.name
        grid = cached_map(resolve_map_path(env.map, base_dir))
        self.names = {kind: str(cfg[kind].name) for kind in INTERFACES}
        self.classes = {kind: registry.load(kind, self.names[kind]) for kind in INTERFACES}
        self.configs = {
            kind: registry.make_config(
                kind, self.classes[kind], {k: v for k, v in cfg[kind].items() if k != "name"}
            )
            for kind in INTERFACES
        }
        evader_cfg, pursuer_cfg = self.configs["evader"], self.configs["pursuer"]
        self.context = Context(
            grid=grid,
            pursuer=Body(
                pursuer_cfg.radius,
                self.settings.speed_ratio * evader_cfg.v_max,
                pursuer_cfg.w_max,
                pursuer_cfg.a_max,
                pursuer_cfg.alpha_max,
            ),
            evader=Body(
                evader_cfg.radius,
                evader_cfg.v_max,
                evader_cfg.w_max,
                evader_cfg.a_max,
                evader_cfg.alpha_max,
            ),
            camera=camera,
            control_dt=1.0 / self.settings.control_hz,
            decision_dt=1.0 / self.settings.decision_hz,
        )
        for config in self.configs.values():  # the checks that need the camera or the rates
            check_context = getattr(config, "check_context", None)
            if check_context is not None:
                check_context(self.context)
        self.config = plain(cfg, resolve=True)
        self.team = self._team(cfg)
        self.team_size = (len(self.team["pursuer"]), len(self.team["evader"]))
        if self.team_size != (1, 1):
            sim, detector = self.classes["sim"], self.classes["detector"]
            assert issubclass(sim, Simulator) and issubclass(detector, Detector)  # registry.load
            check_team(sim, detector, *self.team_size)
            check_room_for_team(self.context, *self.team_size)

    def _team(self, cfg: DictConfig) -> dict[str, list[tuple[str, type, Any]]]:
        """The members of each role as (plugin name, class, config): ``team.pursuers`` and
        ``team.evaders`` (:class:`pegame.config.TeamConfig`); member 0 of a count is the
        role's own plugin. A member naming another plugin keeps only the role's body keys
        (its plugin's own options come from its Config defaults and its node)."""
        team: TeamConfig = typed(cfg.get("team", {}), TeamConfig, "team")
        members: dict[str, list[tuple[str, type, Any]]] = {}
        for role in ("pursuer", "evader"):
            body_keys = {f.name for f in fields(INTERFACES[role].Config)}
            base = {k: v for k, v in plain(cfg[role]).items() if k != "name"}
            entries = team_members(getattr(team, f"{role}s"), role)
            members[role] = []
            for index, entry in enumerate(entries):
                name = str(entry.get("name", self.names[role]))
                options = {k: v for k, v in entry.items() if k != "name"}
                clash = sorted(set(options) & body_keys)
                if clash:
                    raise ConfigError(
                        f"Invalid key 'team.{role}s[{index}].{clash[0]}': every {role} of a team "
                        f"has the role's body. Allowed: set it for all in '{role}.{clash[0]}'; "
                        f"a member sets only its plugin's own options."
                    )
                if not entry or (name == self.names[role] and not options):
                    members[role].append((name, self.classes[role], self.configs[role]))
                    continue
                kept = (
                    base
                    if name == self.names[role]
                    else {k: v for k, v in base.items() if k in body_keys}
                )
                cls = registry.load(role, name)
                node = f"team.{role}s[{index}]"
                config = registry.make_config(role, cls, {**kept, **options}, node)
                members[role].append((name, cls, config))
        return members

    def member(self, kind: str, index: int) -> tuple[type, Any]:
        """The (class, config) of member ``index`` of a role, or of ``kind``'s plugin."""
        if kind in self.team:
            _, cls, config = self.team[kind][index]
            return cls, config
        return self.classes[kind], self.configs[kind]

    def member_names(self, role: str) -> str:
        """The plugin name of a role's members, '+'-joined in member order when they differ."""
        names = list(dict.fromkeys(name for name, _, _ in self.team[role]))
        return "+".join(names)

    def game(self, seed: int) -> Game:
        """The game of this scenario with master seed ``seed``."""
        return Game(self, seed)


class Game:
    """One game: a scenario's plugins (by kind) built with the generators of ``seed``.

    source: a :class:`Scenario`, or a composed config to build one from (with
    ``base_dir``); seed: the master seed, by default the config's ``game.seed``.
    """

    def __init__(
        self,
        source: Scenario | DictConfig,
        seed: int | None = None,
        base_dir: str | Path | None = None,
    ) -> None:
        scenario = source if isinstance(source, Scenario) else Scenario(source, base_dir)
        self.scenario = scenario
        self.seed = scenario.settings.seed if seed is None else seed
        self.context = scenario.context
        streams = dict(zip(STREAMS, np.random.SeedSequence(self.seed).spawn(len(STREAMS))))
        self.spawn_rng = np.random.default_rng(streams["spawn"])
        one = {
            kind: self._build(kind, 0, np.random.default_rng(streams[kind])) for kind in INTERFACES
        }
        n, m = scenario.team_size
        pursuers = (
            Pursuer.narrow(one["pursuer"]),
            *(Pursuer.narrow(self._member("pursuer", k, k)) for k in range(1, n)),
        )
        evaders = (
            Evader.narrow(one["evader"]),
            *(Evader.narrow(self._member("evader", k, k)) for k in range(1, m)),
        )
        detector = Detector.narrow(one["detector"])
        detectors = tuple(
            tuple(
                detector if (i, j) == (0, 0) else Detector.narrow(self._member("detector", 0, i, j))
                for j in range(m)
            )
            for i in range(n)
        )
        estimators = (
            Estimator.narrow(one["estimator"]),
            *(Estimator.narrow(self._member("estimator", 0, j)) for j in range(1, m)),
        )
        self.plugins = GamePlugins(
            Simulator.narrow(one["sim"]),
            detectors,
            estimators,
            pursuers,
            evaders,
            Recorder.narrow(one["recorder"]),
        )

    def _build(self, kind: str, member: int, rng: np.random.Generator) -> Plugin:
        """Member ``member`` of plugin ``kind`` (its class and config from the scenario)
        built with ``rng``."""
        cls, config = self.scenario.member(kind, member)
        return cls(config, self.context, rng)

    def _member(self, kind: str, member: int, *index: int) -> Plugin:
        """A team's extra member ``member`` of ``kind`` (the detectors' and estimators'
        class is the kind's own) built with the generator of ``index``: a stream after
        every 1v1 stream (spawn key ``len(STREAMS)``), so member 0 keeps the 1v1 game's
        generator."""
        rng = np.random.default_rng(member_stream(self.seed, kind, *index))
        return self._build(kind, member, rng)

    def start(self, external: tuple[str, ...] = (), estimate: bool = True) -> TickLoop:
        """Spawn both agents and return the game's tick loop at tick 0 (see TickLoop)."""
        settings = self.scenario.settings
        loop = TickLoop(
            self.plugins,
            self.context,
            settings.ticks,
            settings.decide_every,
            external,
            estimate,
            substeps=settings.substeps,
            turn_order=settings.turn_order,
        )
        loop.start(*spawn_team(self.context, self.spawn_rng, *self.scenario.team_size))
        return loop

    def play(self, out_dir: str | Path, recording_name: str = "game") -> Outcome:
        """Play the game; the recorder (if any) writes ``recording_name`` into ``out_dir``."""
        recorder, solo = self.plugins.recorder, self.scenario.team_size == (1, 1)
        config = {
            **self.scenario.config,
            "game": {**self.scenario.config["game"], "seed": self.seed},
        }
        try:
            loop = self.start()
            recorder.start(str(out_dir), recording_name, config)
            trajectory: list[tuple] = []
            try:
                for _ in range(loop.ticks - loop.step):
                    trajectory.append(trajectory_row(loop.advance()))
                result = self._result(loop.metrics)
            except BaseException as error:
                recorder.abort(error)
                raise
            recorder.finish(result)
        finally:
            self.plugins.sim.close()
        header = TRAJECTORY_HEADER if solo else team_header(*self.scenario.team_size)
        return Outcome(result, trajectory, header)

    def _result(self, metrics: TrackingMetrics | TeamMetrics) -> dict[str, Any]:
        s, names = self.scenario.settings, dict(self.scenario.names)
        names["pursuer"] = self.scenario.member_names("pursuer")
        names["evader"] = self.scenario.member_names("evader")
        return {
            "pairing": pairing(names["pursuer"], names["evader"]),
            "pursuer": names["pursuer"],
            "evader": names["evader"],
            "estimator": names["estimator"],
            "detector": names["detector"],
            "sim": names["sim"],
            "map": self.scenario.env_name,
            "seed": self.seed,
            "speed_ratio": s.speed_ratio,
            "t_max": s.t_max,
            "control_hz": s.control_hz,
            "decision_hz": s.decision_hz,
            "ticks": s.ticks,
            **metrics.summary(),
        }


def write_outcome(outcome: Outcome, out_dir: str | Path) -> None:
    """Write ``trajectory.csv`` then ``result.json`` (last, atomically) into ``out_dir``."""
    out_dir = Path(out_dir)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(outcome.header or TRAJECTORY_HEADER)
    writer.writerows(outcome.trajectory)
    write_atomic(out_dir / "trajectory.csv", buffer.getvalue())
    write_atomic(out_dir / "result.json", json.dumps(outcome.result, indent=2) + "\n")


def summary_line(result: dict[str, Any]) -> str:
    """One line for the terminal: pairing, map, tracking rate, game duration."""
    return (
        f"{result['pairing']} ({result['pursuer']} pursuer vs {result['evader']} evader) on "
        f"{result['map']}: tracking rate {100 * result['tracking_rate']:.1f}% "
        f"(in view {100 * result['visible_rate']:.1f}%) over {result['t_max']:g} s, seed {result['seed']}"
    )
