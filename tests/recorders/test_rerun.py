"""The Rerun recorder, replay and the trajectory figure.

Recordings are read back with Rerun's own tools: ``rerun rrd verify`` and the chunk
reader of rerun-sdk (``rerun.chunk.RrdReader``), counting each entity's rows on the
``step`` timeline.
"""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

from pegame.api import Context, Tick
from pegame.figures import plot_trajectory
from pegame.game import Game
from pegame.grid import OccupancyGrid
from pegame.losses import OCCLUDED, Loss
from pegame.recorders.files import recording_status
from pegame.recorders.rerun import RerunRecorder, recording_id
from pegame.recorders.rerun.scene import HEAVY_PARTICLE
from pegame.replay import find_recordings
from pegame.types import (
    Belief,
    Body,
    BoundingBox,
    Camera,
    Detection,
    Plan,
    Pose,
    SensorFrame,
    Velocity,
)
from pegame.visibility import VisibilityRegion, fov_wedge

SHORT = ["game.t_max=5", "env=hall"]
TICKS = 50  # 5 s at the default 10 Hz
PER_TICK = [
    "/world/pursuer/pose",
    "/world/pursuer/heading",
    "/world/pursuer/fov",
    "/world/pursuer/visible",
    "/world/evader/pose",
    "/world/evader/heading",
    "/world/detection",
    "/world/belief/mean",
    "/plots/tracking/detected",
    "/plots/tracking/rate",
    "/plots/distance/true",
]
STATIC = [
    "/world",
    "/world/map",
    "/camera/frame",
    "/config",
    "/__properties/config",
    "/__properties/result",
]


def read_steps(path: Path) -> tuple[dict[str, list[int]], set[str], list]:
    """(steps per temporal entity, static entities, blueprint stores) of an .rrd file."""
    from rerun.chunk import RrdReader

    reader = RrdReader(path)
    steps: dict[str, list[int]] = defaultdict(list)
    static: set[str] = set()
    for chunk in reader.stream().to_chunks():
        if chunk.is_static:
            static.add(chunk.entity_path)
        else:
            steps[chunk.entity_path].extend(chunk.to_record_batch().column("step").to_pylist())
    return steps, static, reader.blueprints()


def texts(path: Path, entity: str) -> list[tuple[str, str]]:
    """(level, text) of every line of the TextLog ``entity`` of an .rrd file."""
    from rerun.chunk import RrdReader

    lines = []
    for chunk in RrdReader(path).stream().to_chunks():
        if chunk.entity_path == entity:
            batch = chunk.to_record_batch()
            for levels, words in zip(
                batch.column("TextLog:level").to_pylist(), batch.column("TextLog:text").to_pylist()
            ):
                lines += zip(levels, words)
    return lines


@pytest.fixture(scope="module")
def played(tmp_path_factory):
    """A 5 s game on the hall map recorded with recorder=rerun: (game, outcome, out_dir)."""
    from hydra import compose, initialize_config_module

    from pegame.config import register_schema

    register_schema()
    with initialize_config_module(config_module="pegame.conf", version_base=None):
        cfg = compose(config_name="config", overrides=["recorder=rerun", *SHORT])
    out_dir = tmp_path_factory.mktemp("run")
    game = Game(cfg)
    return game, game.play(out_dir), out_dir


def test_one_recording_per_game_named_after_it_and_complete(played):
    _, _, out_dir = played
    assert [p.name for p in find_recordings(out_dir)] == ["game.rrd"]  # no partial file left


def test_rerun_verifies_the_recording(played):
    _, _, out_dir = played
    proc = rrd_verify(out_dir / "game.rrd")
    assert proc.returncode == 0, proc.stderr


def test_entities_have_one_row_per_step(played):
    _, outcome, out_dir = played
    steps, static, blueprints = read_steps(out_dir / "game.rrd")
    assert outcome.result["ticks"] == TICKS
    for entity in PER_TICK:
        assert steps[entity] == list(range(TICKS)), entity
    assert set(STATIC) <= static
    # trajectories every trail_every (5) ticks and at the end
    for entity in ("/world/pursuer/trajectory", "/world/evader/trajectory"):
        assert steps[entity] == [*range(0, TICKS, 5), TICKS - 1], entity
    # decision ticks only (1 Hz of 10 Hz control): paths and goals of both strategies
    for entity in ("/world/pursuer/path", "/world/evader/goal"):
        assert 1 <= len(steps[entity]) <= TICKS // 10 + 1, entity
    assert steps["/events"], "the start of tracking is an event"
    assert not blueprints  # the layout is the directory's, once for all its recordings


def test_the_layout_is_written_once_per_directory_as_a_blueprint_file(played, tmp_path):
    from rerun.chunk import RrdReader

    from pegame.recorders.rerun.blueprint import write_layout

    game, _, out_dir = played
    layout = out_dir / "pegame.rbl"
    assert len(RrdReader(layout).blueprints()) == 1
    assert not RrdReader(layout).recordings()
    before = layout.stat().st_mtime_ns
    context = game.scenario.context  # the next game's recorder finds the file and keeps it
    write_layout(out_dir, "pegame", context, False)
    assert layout.stat().st_mtime_ns == before


def test_fov_wedge_is_placed_at_the_pursuer_pose_every_step(played):
    from rerun.chunk import RrdReader

    game, outcome, out_dir = played
    strips, moves = None, {}
    for chunk in RrdReader(out_dir / "game.rrd").stream().to_chunks():
        if chunk.entity_path != "/world/pursuer/fov":
            continue
        batch = chunk.to_record_batch()
        if chunk.is_static:
            strips = np.array(batch.column("LineStrips3D:strips").to_pylist()[0][0])
        else:
            for step, t, q in zip(
                batch.column("step").to_pylist(),
                batch.column("Transform3D:translation").to_pylist(),
                batch.column("Transform3D:quaternion").to_pylist(),
            ):
                moves[step] = (np.array(t[0]), np.array(q[0]))
    assert strips is not None and sorted(moves) == list(range(TICKS))
    for row in outcome.trajectory:
        step, pose = row[0], Pose(*row[2:5])
        (tx, ty, _), (qx, qy, qz, qw) = moves[step]
        angle = 2.0 * math.atan2(qz, qw)
        assert qx == qy == 0.0
        c, s = math.cos(angle), math.sin(angle)
        placed = np.column_stack(
            [tx + c * strips[:, 0] - s * strips[:, 1], ty + s * strips[:, 0] + c * strips[:, 1]]
        )
        np.testing.assert_allclose(placed, fov_wedge(game.context.camera, pose, n=16), atol=1e-5)


def test_trajectories_are_chained_segments_through_the_agent_poses(played):
    from rerun.chunk import RrdReader

    _, outcome, out_dir = played
    poses = {row[0]: {"pursuer": row[2:4], "evader": row[5:7]} for row in outcome.trajectory}
    for name in ("pursuer", "evader"):
        segments = {}
        for chunk in RrdReader(out_dir / "game.rrd").stream().to_chunks():
            if (
                chunk.entity_path == f"/world/{name}/trajectory" and not chunk.is_static
            ):  # static: style
                batch = chunk.to_record_batch()
                for step, strips in zip(
                    batch.column("step").to_pylist(),
                    batch.column("LineStrips3D:strips").to_pylist(),
                ):
                    segments[step] = np.array(strips[0])
        steps = sorted(segments)
        assert steps == [*range(0, TICKS, 5), TICKS - 1]
        for previous, step in zip([steps[0], *steps], steps):
            start, end = segments[step]
            np.testing.assert_allclose(end[:2], poses[step][name], atol=1e-5)
            np.testing.assert_allclose(start[:2], poses[previous][name], atol=1e-5)


def test_config_and_result_are_recording_properties_with_their_types(played):
    from rerun.chunk import RrdReader

    game, outcome, out_dir = played
    found = {}
    for chunk in RrdReader(out_dir / "game.rrd").stream().to_chunks():
        if chunk.entity_path in ("/__properties/config", "/__properties/result"):
            batch = chunk.to_record_batch()
            found.update(
                {
                    (chunk.entity_path, name): batch.column(name).to_pylist()[0][0]
                    for name in batch.schema.names
                    if name != "rerun.controls.RowId"
                }
            )
    assert found[("/__properties/config", "game.seed")] == game.seed
    assert found[("/__properties/config", "camera.fov")] == pytest.approx(game.context.camera.fov)
    assert found[("/__properties/result", "pairing")] == outcome.result["pairing"]
    assert found[("/__properties/result", "tracking_rate")] == outcome.result["tracking_rate"]
    assert type(found[("/__properties/config", "game.seed")]) is int


def test_recording_does_not_change_the_game(played, compose_config, tmp_path):
    _, outcome, _ = played
    plain = Game(compose_config(["recorder=none", *SHORT])).play(tmp_path)
    assert plain.result == outcome.result
    assert plain.trajectory == outcome.trajectory
    assert not list(tmp_path.glob("*.rrd"))


def test_unwritable_output_dir_warns_and_the_game_goes_on(played, compose_config, tmp_path):
    _, outcome, _ = played
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    with pytest.warns(RuntimeWarning, match="Rerun recording .* disabled"):
        result = Game(compose_config(["recorder=rerun", *SHORT])).play(blocker / "run").result
    assert result == outcome.result


def rrd_verify(path: Path) -> subprocess.CompletedProcess:
    """``rerun rrd verify path``, with the rerun CLI of this Python's rerun-sdk."""
    return subprocess.run(
        [sys.executable, "-m", "rerun", "rrd", "verify", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )


def failing_at_decision(game: Game, count: int, error: BaseException) -> None:
    """Make the game's pursuer raise ``error`` at its ``count``-th decision."""
    decide, calls = game.plugins.pursuer.decide, []

    def failing(observation):
        calls.append(observation.time)
        if len(calls) == count:
            raise error
        return decide(observation)

    game.plugins.pursuer.decide = failing


@pytest.fixture(scope="module")
def failed(tmp_path_factory):
    """The recording dir of a 5 s game whose pursuer raises at its third decision, at
    step 20 (decisions at 1 Hz of 10 Hz control), before that tick is logged."""
    from pegame.config import compose

    out_dir = tmp_path_factory.mktemp("failed")
    game = Game(compose(["recorder=rerun", *SHORT]))
    failing_at_decision(game, 3, RuntimeError("pursuer broke"))
    with pytest.raises(RuntimeError, match="pursuer broke"):
        game.play(out_dir)
    return out_dir


def test_a_failed_game_leaves_a_failed_recording_readable_up_to_its_failure(failed):
    from rerun.chunk import RrdReader

    assert [p.name for p in find_recordings(failed)] == ["game.failed.rrd"]
    path = failed / "game.failed.rrd"
    proc = rrd_verify(path)
    assert proc.returncode == 0, proc.stderr
    steps, static, _ = read_steps(path)
    for entity in PER_TICK:
        assert steps[entity] == list(range(20)), entity  # flushed at the failure
    assert "/__properties/failure" in static and "/__properties/result" not in static
    failure = {}
    for chunk in RrdReader(path).stream().to_chunks():
        batch = chunk.to_record_batch()
        if chunk.entity_path == "/__properties/failure":
            failure.update(
                {
                    name: batch.column(name).to_pylist()[0][0]
                    for name in batch.schema.names
                    if name != "rerun.controls.RowId"
                }
            )
    events = texts(path, "/events")
    assert ("ERROR", "game failed after step 19: RuntimeError: pursuer broke") in events
    assert failure == {"error": "RuntimeError", "message": "pursuer broke", "step": 19}


def recordings(out_dir: Path) -> list[str]:
    """The names of the recording files in ``out_dir`` (not its layout file), sorted."""
    return sorted(p.name for p in out_dir.iterdir() if recording_status(p))


def test_a_finished_game_supersedes_its_failed_recording(tmp_path):
    context = small_context()
    for abort in (True, False):
        recorder = RerunRecorder(RerunRecorder.Config(), context, None)
        recorder.start(str(tmp_path), "game_3", {})
        assert recordings(tmp_path) == (
            [] if abort else ["game_3.failed.rrd"]
        )  # held in memory meanwhile
        for tick in synthetic_ticks(context, 6):
            recorder.log(tick)
        if abort:
            recorder.abort(KeyboardInterrupt())
            assert recordings(tmp_path) == ["game_3.failed.rrd"]
        else:
            recorder.finish({})
    assert recordings(tmp_path) == ["game_3.rrd"]
    assert rrd_verify(tmp_path / "game_3.rrd").returncode == 0


def test_a_game_that_fails_before_its_first_tick_leaves_a_failed_recording(tmp_path):
    recorder = RerunRecorder(RerunRecorder.Config(), small_context(), None)
    recorder.start(str(tmp_path), "game", {"game": {"seed": 1}})
    recorder.abort(ValueError("bad spawn"))
    assert recordings(tmp_path) == ["game.failed.rrd"]
    steps, static, _ = read_steps(tmp_path / "game.failed.rrd")
    assert steps["/events"] == [0] and "/world/map" in static


# ------------------------------------------------------------ the recorder alone


def small_context() -> Context:
    data = np.zeros((60, 80), dtype=np.int8)
    data[:, :2] = data[:, -2:] = data[:2, :] = data[-2:, :] = 100
    data[20:40, 50:52] = 100
    grid = OccupancyGrid(data, 0.1, origin=(-1.0, 2.0, 0.3), name="box")
    return Context(grid, Body(0.2, 0.5, 1.8), Body(0.25, 0.5, 1.8), Camera(), 0.1, 1.0)


def synthetic_ticks(context: Context, count: int) -> list[Tick]:
    """Ticks with particles, weights, N_eff, candidates, a mode and a lost detection (an
    occluded evader at tick 4)."""
    rng = np.random.default_rng(1)
    ticks = []
    plans = {}
    for step in range(count):
        pursuer = Pose(1.0 + 0.05 * step, 4.5, 0.2)
        evader = Pose(3.5, 4.0 + 0.02 * step, 1.0)
        detection = None
        if step < 4 or step >= 8:
            detection = Detection(BoundingBox(300, 200, 40, 90), 2.5, (evader.x, evader.y), 0.9)
        particles = np.column_stack([rng.normal(3.5, 0.3, (1000, 2)), rng.uniform(-3, 3, 1000)])
        weights = rng.random(1000)
        belief = Belief(
            (3.4, 4.1), particles=particles, weights=weights / weights.sum(), n_eff=700.0
        )
        decision = step // 5  # a new plan every 5 ticks, the same objects in between
        if decision not in plans:
            plans[decision] = (
                Plan(
                    goal=(2.0 + decision, 4.0),
                    path=np.array([[1.0, 4.5], [2.0 + decision, 4.0]]),
                    info={"mode": "track" if decision % 2 == 0 else "search"},
                ),
                Plan(
                    goal=(4.0, 5.0),
                    path=np.array([[3.5, 4.0], [4.0, 5.0]]),
                    info={"candidates": np.array([[4.0, 5.0], [5.0, 3.0], [2.0 + decision, 6.0]])},
                ),
            )
        visible = VisibilityRegion(context.grid, pursuer, context.camera)
        ticks.append(
            Tick.one_on_one(
                step,
                0.1 * step,
                pursuer,
                evader,
                SensorFrame(0.1 * step, pursuer),
                detection,
                belief,
                visible,
                detection is not None,
                (Velocity(), Velocity()),
                plans[decision],
                (Loss(0, 0, step, OCCLUDED),) if step == 4 else (),
            )
        )
    return ticks


def test_recorder_logs_particles_candidates_n_eff_and_events(tmp_path):
    context = small_context()
    ticks = synthetic_ticks(context, 23)
    recorder = RerunRecorder(RerunRecorder.Config(flush_every=10, max_particles=100), context, None)
    recorder.start(str(tmp_path), "game_7", {"pursuer": {"name": "smart"}, "game": {"seed": 7}})
    for tick in ticks:
        recorder.log(tick)
    recorder.finish({"tracking_rate": 0.8, "mean_estimation_error": None})
    steps, static, _ = read_steps(tmp_path / "game_7.rrd")
    every = list(range(23))
    # the particles every particles_every (2) ticks; the viewer holds the last cloud
    assert steps["/world/belief/particles"] == list(range(0, 23, 2))
    for entity in (
        "/plots/n_eff",
        "/plots/distance/estimate_error",
        "/world/detection",
    ):
        assert steps[entity] == every, entity
    # a new plan every 5 ticks; candidates only then
    assert steps["/world/evader/candidates"] == [0, 5, 10, 15, 20]
    # start, lost at 4, reacquired at 8, pursuer modes at 0, 5, 10, 15, 20, game over at 22
    assert sorted(steps["/events"]) == [0, 0, 4, 5, 8, 10, 15, 20, 22]
    assert "/__properties/result" in static
    assert steps["/losses"] == [4]
    assert texts(tmp_path / "game_7.rrd", "/losses") == [
        ("WARN", "pursuer 0 lost evader 0: occluded")
    ]
    assert ("WARN", "evader lost after 0.4 s tracked: occluded") in texts(
        tmp_path / "game_7.rrd", "/events"
    )


def test_spawn_sends_live_to_a_viewer_as_well_as_to_the_file(monkeypatch, tmp_path):
    import rerun as rr

    spawned = []
    monkeypatch.setattr(rr, "spawn", lambda **kwargs: spawned.append(kwargs))
    # No screen here: the viewer's gRPC sink is replaced by a second file.
    monkeypatch.setattr(rr, "GrpcSink", lambda: rr.FileSink(str(tmp_path / "live.rrd")))
    context = small_context()
    ticks = synthetic_ticks(context, 12)
    for spawn in (False, True):
        recorder = RerunRecorder(RerunRecorder.Config(spawn=spawn), context, None)
        recorder.start(str(tmp_path), "game", {})
        for tick in ticks:
            recorder.log(tick)
        recorder.finish({})
        assert spawned == ([{"connect": False}] if spawn else [])
    live, _, _ = read_steps(tmp_path / "live.rrd")
    assert live["/world/pursuer/pose"] == list(range(12))


def test_bad_recorder_options_are_config_errors():
    from pegame.errors import ConfigError
    from pegame.registry import make_config

    with pytest.raises(ConfigError, match="recorder.flush_every"):
        make_config("recorder", RerunRecorder, {"flush_every": 0})
    with pytest.raises(ConfigError, match="recorder.jpeg_quality"):
        make_config("recorder", RerunRecorder, {"jpeg_quality": 101})


def test_particles_are_subsampled_and_coloured_by_weight(tmp_path):
    from rerun.chunk import RrdReader

    context = small_context()
    recorder = RerunRecorder(RerunRecorder.Config(max_particles=100), context, None)
    recorder.start(str(tmp_path), "game", {})
    tick = synthetic_ticks(context, 1)[0]
    particles_before = tick.belief.particles.copy()
    recorder.log(tick)
    recorder.finish({})
    assert np.array_equal(tick.belief.particles, particles_before)
    chunks = [
        c
        for c in RrdReader(tmp_path / "game.rrd").stream().to_chunks()
        if c.entity_path == "/world/belief/particles" and not c.is_static
    ]
    batch = chunks[0].to_record_batch()
    positions = batch.column("Points3D:positions").to_pylist()[0]
    colors = batch.column("Points3D:colors").to_pylist()[0]
    assert len(positions) == len(colors) == 100
    assert len(set(colors)) > 10


def test_particles_of_equal_weight_are_sent_with_one_colour(tmp_path):
    """After a resampling every weight is equal: the row holds one colour, which Rerun
    repeats over its points (the heaviest shade, as each point had before)."""
    from rerun.chunk import RrdReader

    context = small_context()
    config = RerunRecorder.Config(max_particles=100, particles_every=1)
    recorder = RerunRecorder(config, context, None)
    recorder.start(str(tmp_path), "game", {})
    weighted, resampled = synthetic_ticks(context, 2)
    n = len(resampled.belief.particles)
    equal = Belief(
        resampled.belief.mean, particles=resampled.belief.particles, weights=np.full(n, 1.0 / n)
    )
    for tick in (weighted, dataclasses.replace(resampled, beliefs=(equal,))):
        recorder.log(tick)
    recorder.finish({})
    (chunk,) = [
        c
        for c in RrdReader(tmp_path / "game.rrd").stream().to_chunks()
        if c.entity_path == "/world/belief/particles" and not c.is_static
    ]
    batch = chunk.to_record_batch()
    positions = batch.column("Points3D:positions").to_pylist()
    colors = batch.column("Points3D:colors").to_pylist()
    assert [len(p) for p in positions] == [100, 100]
    assert len(colors[0]) == 100 and len(set(colors[0])) > 10
    r, g, b, a = HEAVY_PARTICLE.astype(int)
    assert colors[1] == [r << 24 | g << 16 | b << 8 | a]


def test_recording_id_is_deterministic_per_place_and_config(tmp_path):
    config = {"game": {"seed": 3}}
    assert recording_id(tmp_path, "game", config) == recording_id(tmp_path, "game", dict(config))
    assert recording_id(tmp_path, "game", config) != recording_id(
        tmp_path / "other", "game", config
    )
    assert recording_id(tmp_path, "game", config) != recording_id(
        tmp_path, "game", {"game": {"seed": 4}}
    )


def test_importing_the_null_recorder_and_replay_does_not_import_rerun():
    code = (
        "import sys, pegame.recorders, pegame.recorders.none, pegame.recorders.files, pegame.replay; "
        "print('rerun' in sys.modules)"
    )
    assert (
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip()
        == "False"
    )


# ----------------------------------------------------------------------- figures


def test_plot_trajectory_writes_a_png(played, tmp_path):
    game, outcome, _ = played
    path = plot_trajectory(
        game.context.grid,
        outcome.trajectory,
        tmp_path / "trajectory.png",
        pairing=outcome.result["pairing"],
        tracking_rate=outcome.result["tracking_rate"],
    )
    data = path.read_bytes()
    assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 10_000
    assert not [p for p in tmp_path.iterdir() if p.name != "trajectory.png"], (
        "no temporary file left"
    )


def test_plot_trajectory_takes_csv_text_and_a_rotated_map(tmp_path):
    grid = small_context().grid
    rows = [
        [str(v) for v in (k, 0.1 * k, 1 + 0.1 * k, 4.5, 0.0, 3.5, 4 + math.sin(k), 1.0, 1, 1)]
        for k in range(20)
    ]
    path = plot_trajectory(
        grid, rows, tmp_path / "trajectory.png", title="S-R (smart vs random) on box: " * 3
    )
    assert path.stat().st_size > 1000


def test_detection_boxes_are_logged_on_the_image_plane_only_when_there_are_images(tmp_path):
    context = small_context()
    ticks = synthetic_ticks(context, 6)
    width, height = context.camera.image_width, context.camera.image_height
    rgb = np.zeros((height, width, 3), dtype=np.uint8)
    with_images = [
        dataclasses.replace(t, frames=(dataclasses.replace(t.frame, rgb=rgb),)) for t in ticks
    ]
    for name, played in (("grid", ticks), ("images", with_images)):
        recorder = RerunRecorder(RerunRecorder.Config(), context, None)
        recorder.start(str(tmp_path / name), "game", {})
        for tick in played:
            recorder.log(tick)
        recorder.finish({})
    grid, _, _ = read_steps(tmp_path / "grid" / "game.rrd")
    images, _, _ = read_steps(tmp_path / "images" / "game.rrd")
    assert "/camera/detection" not in grid and "/world/detection" in grid
    assert images["/camera/detection"] == list(range(6))
    assert images["/camera/image"] == [0]  # image_every (10) ticks


def test_particle_shades_read_only_the_held_part_of_a_reused_buffer():
    import warnings

    from pegame.recorders.rerun.columns import ParticleRows

    rows = ParticleRows(2, 10, 0.02)
    rows.weights[:] = 3e38  # what a reused buffer may hold past a row's particles
    particles = np.array([[1.0, 2.0, 0.0], [3.0, 4.0, 0.0]])
    rows.add(0, 0.0, particles, np.array([1e-30, 0.5e-30]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow from the entries past the row
        _, _, positions, sizes, shades, counts = rows.take()
    assert sizes.tolist() == [2] and counts.tolist() == [2]
    assert shades.tolist() == [255, 128] and positions[:, :2].tolist() == [[1, 2], [3, 4]]
