"""Teams: N pursuers against M evaders in the one tick loop, and the 1v1 game as its
special case."""

from __future__ import annotations

import csv
import math
import subprocess
import sys

import numpy as np
import pytest

from pegame.api import Detection, Detector, OneOnOneSimulator, Simulator, fuse_detections
from pegame.config import compose
from pegame.detectors.oracle import OracleDetector
from pegame.errors import ConfigError, SpawnError, require
from pegame.estimators.kalman import KalmanEstimator
from pegame.game import (
    TRAJECTORY_HEADER,
    Game,
    spawn,
    spawn_team,
    team_header,
    trajectory_row,
    write_outcome,
)
from pegame.grid import FREE, OCCUPIED, OccupancyGrid, save_map
from pegame.loop import check_team
from pegame.metrics import TeamMetrics, TrackingMetrics
from pegame.pursuers.cooperative import weighted_kmeans
from pegame.sims.grid import GridSimulator
from pegame.types import EMPTY_BELIEF, Belief, BoundingBox, Pose
from pegame.visibility import UnionRegion, VisibilityRegion, in_view

SHORT = ["recorder=none", "game.t_max=8"]


def team_game(*overrides: str, seed: int = 0) -> Game:
    return Game(compose([*SHORT, *overrides, f"game.seed={seed}"]))


@pytest.fixture(scope="module")
def solo() -> Game:
    """A 1v1 game on the enclosed map, for its context and plugins."""
    return team_game()


def detection_at(x: float, y: float, depth: float = 2.0) -> Detection:
    return Detection(BoundingBox(300, 100, 40, 200), depth, (x, y))


# ------------------------------------------------------------------ 1v1, the special case


def test_member_zero_of_a_team_gets_the_1v1_generators_and_the_others_their_own(solo):
    team = team_game("team.pursuers=3", "team.evaders=2")
    for kind in ("pursuer", "evader", "detector", "estimator", "sim"):
        assert (
            getattr(team.plugins, kind).rng.bit_generator.state
            == getattr(solo.plugins, kind).rng.bit_generator.state
        )
    states = [p.rng.bit_generator.state["state"]["state"] for p in team.plugins.pursuers]
    detectors = [
        d.rng.bit_generator.state["state"]["state"] for row in team.plugins.detectors for d in row
    ]
    assert len(set(states)) == 3 and len(set(detectors)) == 6


def test_a_team_spawn_starts_with_the_1v1_pair_of_the_same_seed(solo):
    game = team_game("team.pursuers=3", "team.evaders=2", seed=4)
    pursuers, evaders = spawn_team(game.context, game.spawn_rng, 3, 2)
    single = Game(solo.scenario, 4)
    assert (pursuers[0], evaders[0]) == spawn(single.context, single.spawn_rng)


def test_team_metrics_of_one_pursuer_and_one_evader_equal_the_1v1_measures(solo):
    game = solo
    rng = np.random.default_rng(3)
    single, team = TrackingMetrics(0.1), TeamMetrics(game.context, 1, 1)
    for _ in range(200):
        p, e = Pose(*rng.uniform(1, 5, 2)), Pose(*rng.uniform(1, 5, 2))
        detected, seen = bool(rng.random() < 0.6), bool(rng.random() < 0.7)
        belief = Belief(mean=tuple(rng.uniform(1, 5, 2))) if rng.random() < 0.8 else EMPTY_BELIEF
        detection = detection_at(e.x, e.y) if detected else None
        single.add(p, e, detected, seen, belief)
        team.add((p,), (e,), ((detection,),), ((seen,),), (belief,))
    summary = team.summary()
    assert {k: summary[k] for k in single.summary()} == single.summary()


# ------------------------------------------------------------------------------- config


@pytest.mark.parametrize(
    ("value", "allowed"),
    [
        ("0", "from 1 to 16"),
        ("17", "from 1 to 16"),
        ("[]", "list of members"),
        ("[3]", "Invalid member"),
    ],
)
def test_a_bad_team_size_is_a_config_error_naming_the_key_and_what_is_allowed(value, allowed):
    with pytest.raises(ConfigError) as info:
        team_game(f"team.pursuers={value}")
    assert "team.pursuers" in str(info.value) and allowed in str(info.value)


def test_a_member_cannot_change_the_role_s_body():
    with pytest.raises(ConfigError, match=r"team.pursuers\[1\].radius"):
        team_game("team.pursuers=[smart,{name:random,radius:0.3}]")


@pytest.mark.parametrize(
    ("member", "key"),
    [
        ("{name:smart,k_v:-1}", "team.pursuers[1].k_v"),  # the plugin's own range check
        ("{name:smart,kv:1}", "team.pursuers[1].kv"),  # an unknown key
    ],
)
def test_a_bad_member_option_names_the_member_s_key(member, key):
    with pytest.raises(ConfigError) as info:
        team_game(f"team.pursuers=[random,{member}]")
    assert f"'{key}'" in str(info.value)


def test_a_check_written_under_its_group_is_moved_under_the_node():
    """A plugin written before keys were relative names 'pursuer.gain' itself."""
    with pytest.raises(ConfigError) as info:
        require(False, "pursuer.gain", "a positive number", -1.0)
    moved = info.value.under("team.pursuers[2]", "pursuer")
    assert (
        str(moved) == "Invalid value for 'team.pursuers[2].gain': -1.0. Allowed: a positive number."
    )
    assert str(info.value.under("pursuer", "pursuer")).startswith(
        "Invalid value for 'pursuer.gain'"
    )


def test_a_heterogeneous_team_plays_one_plugin_per_member_with_its_own_options():
    game = team_game("team.pursuers=[random,{name:smart,standoff:1.0}]", "pursuer=smart")
    first, second = game.plugins.pursuers
    assert type(first).__name__ == "RandomPursuer" and game.plugins.pursuer is first
    assert type(second).__name__ == "SmartPursuer" and second.config.standoff == 1.0
    assert game.play("unused").result["pursuer"] == "random+smart"


@pytest.mark.slow
def test_the_cli_exits_2_on_a_bad_team_value_with_the_allowed_values():
    run = subprocess.run(
        [sys.executable, "-m", "pegame", "team.evaders=-1", "recorder=none"],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2
    assert "team.evaders" in run.stderr + run.stdout and "from 1 to 16" in run.stderr + run.stdout


class _SoloSimulator(GridSimulator):
    teams = False


class _Blind(Detector):
    def detect(self, frame):
        return None


def test_a_simulator_without_teams_or_a_detector_that_cannot_tell_evaders_apart_is_refused():
    with pytest.raises(ConfigError, match="plays one pursuer and one evader"):
        check_team(_SoloSimulator, OracleDetector, 2, 1)
    with pytest.raises(ConfigError, match="cannot tell evaders apart"):
        check_team(GridSimulator, _Blind, 1, 2)
    check_team(GridSimulator, _Blind, 3, 1)  # one evader: no identity needed
    assert Simulator.teams and not OneOnOneSimulator.teams and OracleDetector.identifies


# -------------------------------------------------------------------------------- spawn


def test_the_spawn_keeps_bodies_apart_where_the_old_one_overlapped_them():
    # hall seed 1: the old spawn put the evader 0.32 m from the pursuer (radii 0.2 + 0.25)
    game = team_game("env=hall", seed=1)
    pursuer, evader = spawn(game.context, game.spawn_rng)
    assert pursuer.distance_to(evader) >= 0.45


@pytest.mark.parametrize("seed", range(4))
def test_a_team_spawns_apart_with_every_evader_in_some_pursuer_s_view(seed):
    game = team_game("team.pursuers=3", "team.evaders=3", seed=seed)
    pursuers, evaders = spawn_team(game.context, game.spawn_rng, 3, 3)
    bodies = [(p, 0.2) for p in pursuers] + [(e, 0.25) for e in evaders]
    for a, (pa, ra) in enumerate(bodies):
        for pb, rb in bodies[a + 1 :]:
            assert pa.distance_to(pb) >= ra + rb
    camera, grid = game.context.camera, game.context.grid
    for e in evaders:
        assert any(in_view(grid, camera, p, (e.x, e.y)) for p in pursuers)


def test_a_team_with_no_room_is_a_spawn_error_naming_the_map_and_the_team(tmp_path):
    data = np.full((24, 24), OCCUPIED, dtype=np.int8)
    data[2:22, 2:22] = FREE  # a 1 m x 1 m room
    save_map(OccupancyGrid(data, 0.05, name="closet"), tmp_path / "closet.yaml")
    with pytest.raises(SpawnError) as info:
        team_game(f"env.map={tmp_path / 'closet.yaml'}", "env.name=closet", "team.pursuers=8")
    message = str(info.value)
    assert "closet" in message and "8 pursuer(s)" in message and "1 evader(s)" in message


# -------------------------------------------------------------------- sensing and belief


def test_the_union_region_holds_the_cells_of_any_member(solo):
    grid, camera = solo.context.grid, solo.context.camera
    regions = [
        VisibilityRegion(grid, Pose(4, 4, 0.3), camera),
        VisibilityRegion(grid, Pose(9, 6, 2.5), camera),
    ]
    union = UnionRegion(regions)
    cells = np.arange(0, grid.width * grid.height, 7)
    expected = (regions[0].mask | regions[1].mask).ravel()[cells]
    assert np.array_equal(UnionRegion(regions).holds(cells), expected)
    assert np.array_equal(union.mask.ravel()[cells], expected)
    r0, r1, c0, c1 = union.bounds
    rows, cols = np.nonzero(union.mask)
    assert rows.min() >= r0 and rows.max() < r1 and cols.min() >= c0 and cols.max() < c1


def test_detections_of_one_evader_fuse_at_the_mean_credited_to_the_nearest_pursuer():
    pursuers = (Pose(0, 0), Pose(5, 5), Pose(9, 9))
    far, near = detection_at(2.0, 2.0, depth=3.0), detection_at(2.2, 1.8, depth=1.0)
    pursuer, fused = fuse_detections(pursuers, [far, None, near])
    assert pursuer == pursuers[2] and fused.position == pytest.approx((2.1, 1.9))
    assert fuse_detections(pursuers, [None, None, None]) == (pursuers[0], None)


def test_two_pursuers_detections_shrink_the_kalman_covariance_more_than_one(solo):
    one, two = (KalmanEstimator(KalmanEstimator.Config(), solo.context, None) for _ in range(2))
    poses = (Pose(0, 0), Pose(4, 4))
    for estimator, extra in ((one, None), (two, detection_at(3.0, 3.0))):
        estimator.reset(poses, [detection_at(3.0, 3.0), extra], None)
        belief = estimator.update(0.1, poses, [detection_at(3.05, 3.0), extra], None)
    assert np.trace(two._belief().covariance) < np.trace(one._belief().covariance)
    assert belief.mean == pytest.approx((3.0, 3.0), abs=0.1)


@pytest.mark.parametrize("estimator", ["particle_filter", "kalman", "last_seen"])
def test_every_estimator_plays_a_team_with_one_belief_per_evader(estimator):
    game = team_game(f"estimator={estimator}", "team.pursuers=2", "team.evaders=2")
    loop = game.start()
    while not loop.done:
        tick = loop.advance()
    assert len(tick.beliefs) == 2 and len(tick.detections) == 2
    assert any(b.mean is not None for b in tick.beliefs)
    for row in tick.detections:
        for j, detection in enumerate(row):
            assert detection is None or detection.evader == j


# ------------------------------------------------------------------------------ measures


def test_handoffs_count_custody_passing_from_pursuer_to_pursuer(solo):
    metrics = TeamMetrics(solo.context, 2, 1)
    seen = detection_at(1, 1)
    # A sees; A and B see; B sees (a handoff); nobody; A sees (a reacquisition, not a handoff)
    for row in ((seen, None), (seen, seen), (None, seen), (None, None), (seen, None)):
        metrics.add(
            (Pose(0, 0), Pose(3, 3)),
            (Pose(1, 1),),
            tuple((d,) for d in row),
            ((True,), (True,)),
            (EMPTY_BELIEF,),
        )
    summary = metrics.summary()
    assert summary["handoffs"] == 1
    assert summary["tracking_rate"] == pytest.approx(0.8)
    assert summary["tracking_rate_per_pursuer"] == [pytest.approx(0.6), pytest.approx(0.4)]


def test_a_1v1_ticks_row_is_its_team_row_under_the_1v1_names():
    tick = team_game().start().advance()
    row = trajectory_row(tick)
    assert len(row) == len(TRAJECTORY_HEADER) == len(team_header(1, 1))
    p, e = tick.pursuer, tick.evader
    assert row[2:8] == (p.x, p.y, p.theta, e.x, e.y, e.theta)
    assert row[8:] == (int(tick.detection is not None), int(tick.in_view))


def test_a_team_game_writes_every_agent_and_the_team_measures(tmp_path):
    game = team_game("team.pursuers=2", "team.evaders=2", "pursuer=cooperative", seed=2)
    outcome = game.play(tmp_path)
    write_outcome(outcome, tmp_path)
    rows = list(csv.reader((tmp_path / "trajectory.csv").open()))
    assert tuple(rows[0]) == team_header(2, 2) and len(rows) == 81
    result = outcome.result
    assert result["pursuers"] == 2 and result["evaders"] == 2
    assert result["tracking_rate"] == pytest.approx(
        np.mean(result["tracking_rate_per_evader"]), abs=1e-6
    )
    assert 0 < result["coverage"] < 1 and result["pairing"] == "cooperative-S"
    again = team_game("team.pursuers=2", "team.evaders=2", "pursuer=cooperative", seed=2)
    assert again.play(tmp_path).result == result


# -------------------------------------------------------------------------- strategies


def test_weighted_kmeans_finds_two_separated_clouds_and_their_weights():
    rng = np.random.default_rng(0)
    points = np.vstack([rng.normal((0, 0), 0.1, (300, 2)), rng.normal((5, 0), 0.1, (100, 2))])
    weights = np.full(400, 1 / 400)
    centres, mass = weighted_kmeans(points, weights, 2, 8)
    order = np.argsort(centres[:, 0])
    assert centres[order] == pytest.approx(np.array([[0, 0], [5, 0]]), abs=0.05)
    assert mass[order] == pytest.approx([0.75, 0.25])


def test_cooperative_pursuers_split_between_the_clusters_of_a_lost_evader():
    game = team_game("team.pursuers=2", "pursuer=cooperative")
    loop = game.start()
    member = game.plugins.pursuers[0]
    cloud = np.vstack([np.tile([3.0, 3.0, 0.0], (500, 1)), np.tile([12.0, 12.0, 0.0], (500, 1))])
    belief = Belief(mean=(7.5, 7.5), particles=cloud, weights=np.full(1000, 1e-3))
    team = loop.pursuer_observation(0).team
    lost = type(team)(
        0,
        0,
        (Pose(3.5, 3.0), Pose(11.5, 12.0)),
        ((None,), (None,)),
        (belief,),
        team.regions,
        team.union,
    )
    tasks = member.assign(lost)
    assert tasks[0].goal == pytest.approx((3.0, 3.0), abs=0.1)
    assert tasks[1].goal == pytest.approx((12.0, 12.0), abs=0.1)


def test_the_team_evader_hides_from_the_nearest_pursuer_of_each_candidate(solo):
    evader = solo.plugins.evader
    me, a = Pose(4.0, 4.0), Pose(6.0, 6.0, 0.5)
    alone = evader.team_escape(me, (a, a))
    reference = evader.search.escape_reference(me, a)
    assert (alone.cell, alone.cost, alone.count) == (
        reference.cell,
        reference.cost,
        reference.count,
    )
    # A second pursuer standing on the 1v1 escape point moves the evader's choice away.
    goal = tuple(evader.search.centres(alone.cell))
    guarded = evader.team_escape(me, (a, Pose(goal[0], goal[1], math.pi)))
    assert guarded.cell != alone.cell


def test_a_team_recording_shows_every_agent_fov_and_belief(tmp_path):
    from rerun.chunk import RrdReader

    game = team_game("recorder=rerun", "game.t_max=3", "team.pursuers=3", "team.evaders=2")
    game.play(tmp_path, "team")
    paths = {chunk.entity_path for chunk in RrdReader(tmp_path / "team.rrd").stream().to_chunks()}
    for member in ("pursuer_1/pose", "pursuer_2/fov", "evader_1/pose", "belief_1/mean"):
        assert f"/world/{member}" in paths
    assert "/world/pursuer/pose" in paths and "/world/belief/mean" in paths


def test_the_trajectory_figure_draws_every_member_of_a_team(tmp_path):
    from pegame.figures import agents, plot_trajectory

    game = team_game("team.pursuers=2", "team.evaders=3", "game.t_max=2")
    outcome = game.play(tmp_path)
    path = plot_trajectory(
        game.context.grid, outcome.trajectory, tmp_path / "t.png", header=outcome.header
    )
    assert path.stat().st_size > 0
    labels = [label for label, _, _ in agents(outcome.header)]
    assert labels == ["pursuer 0", "pursuer 1", "evader 0", "evader 1", "evader 2"]
    assert [label for label, _, _ in agents(team_header(1, 1)[:2] + ("pursuer_x", "evader_x"))] == [
        "pursuer",
        "evader",
    ]


def test_the_pettingzoo_env_plays_teams_and_passes_the_parallel_api_test():
    from pettingzoo.test import parallel_api_test

    from pegame.envs import parallel_env

    overrides = ["env=hall", "game.t_max=4", "team.pursuers=2", "team.evaders=2"]
    env = parallel_env(overrides=overrides, decision_period=1.0)
    assert env.possible_agents == ["pursuer_0", "pursuer_1", "evader_0", "evader_1"]
    parallel_api_test(env, num_cycles=5)
    env.reset(seed=1)
    actions = {agent: np.zeros(2, dtype=np.float32) for agent in env.agents}
    _, rewards, _, _, _ = env.step(actions)
    assert (
        rewards["pursuer_0"] == rewards["pursuer_1"] == -(rewards["evader_0"] + rewards["evader_1"])
    )
