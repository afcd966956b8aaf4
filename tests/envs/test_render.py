"""``render_mode="rgb_array"`` in the Gymnasium and PettingZoo envs: the frame shows the
game's current state, and Gymnasium's RecordVideo records episodes with it."""

from __future__ import annotations

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

import pegame.envs  # noqa: F401 - registers the envs
from pegame.envs import parallel_env
from pegame.errors import ConfigError
from pegame.render import EVADER, PURSUER

SHORT = ["game.t_max=3", "env=enclosed"]


def colour_centre(image: np.ndarray, colour: tuple[int, int, int]) -> np.ndarray:
    """The mean (column, row) of the pixels of exactly ``colour``."""
    rows, cols = np.nonzero(np.all(image == colour, axis=2))
    assert len(rows), f"no pixel of {colour}"
    return np.array([cols.mean(), rows.mean()])


def test_the_frame_follows_the_bodies():
    env = gymnasium.make("pegame/Pursuit-v0", overrides=SHORT, render_mode="rgb_array")
    env.reset(seed=3)
    game = env.unwrapped.game
    before = env.render()
    assert before.shape == (480, 480, 3) and before.dtype == np.uint8
    draw = game._renderer[1]
    for colour, pose in ((PURSUER, game.loop.pursuer), (EVADER, game.loop.evader)):
        expected = draw.pixel([pose.x], [pose.y])[0]
        assert np.abs(colour_centre(before, colour) - expected).max() < 6  # px, the disc's centre
    for _ in range(5):
        env.step(np.array([1.0, 0.0], dtype=np.float32))
    after = env.render()
    moved = colour_centre(after, PURSUER) - colour_centre(before, PURSUER)
    assert np.hypot(*moved) > 3  # it drove forward
    assert env.metadata["render_fps"] == pytest.approx(10.0)


@pytest.mark.slow
def test_record_video_records_an_episode(tmp_path):
    pytest.importorskip("moviepy")
    from gymnasium.wrappers import RecordVideo

    env = RecordVideo(
        gymnasium.make("pegame/Evasion-v0", overrides=SHORT, render_mode="rgb_array"),
        str(tmp_path / "videos"),
        episode_trigger=lambda episode: True,
    )
    env.reset(seed=0)
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        done = terminated or truncated
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 1000


def test_the_parallel_env_draws_every_member_and_refuses_an_unknown_mode():
    env = parallel_env(
        overrides=[*SHORT, "team.pursuers=2", "team.evaders=2"], render_mode="rgb_array"
    )
    env.reset(seed=1)
    image = env.render()
    rows, _ = np.nonzero(np.all(image == PURSUER, axis=2))
    assert len(rows) > 2 * 20  # two pursuer discs
    assert parallel_env(overrides=SHORT).render() is None  # no render mode: nothing drawn
    with pytest.raises(
        ConfigError, match="Invalid value for 'render_mode': 'human'. Allowed: None or 'rgb_array'"
    ):
        parallel_env(overrides=SHORT, render_mode="human")
