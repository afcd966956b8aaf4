"""The batched game refuses what its kernels do not play (pegame.vector.game.check_playable):
each setting alone is a one-paragraph ConfigError naming the key, its value and what the
batched game plays; a config that sets several is refused once, naming them all."""

from __future__ import annotations

import pytest

from pegame.envs.vector import vector_env
from pegame.errors import ConfigError

BASE = ["env=hall", "evader.model=action"]


@pytest.mark.parametrize(
    ("override", "key", "value", "allowed"),
    [
        ("team.pursuers=2", "team.pursuers", "2", "1"),
        ("team.evaders=3", "team.evaders", "3", "1"),
        ("game.turn_order=evader_first", "game.turn_order", "'evader_first'", "'simultaneous'"),
    ],
)
def test_each_setting_it_does_not_play_is_refused_by_name(override, key, value, allowed):
    with pytest.raises(ConfigError) as error:
        vector_env(2, overrides=[*BASE, override], opponent="random")
    message = str(error.value)
    assert message.startswith(f"Invalid value for '{key}' in a batched env: {value}. ")
    assert f"Allowed: {allowed}" in message and "use the single env" in message
    assert "\n" not in message


def test_a_belief_in_a_team_games_observation_is_refused():
    team = ["env=hall", "team.pursuers=2"]
    with pytest.raises(ConfigError, match=r"'belief' in a batched env: True\. Allowed: False"):
        vector_env(2, overrides=team, role="both", belief=True)


@pytest.mark.parametrize(("group", "name"), [("sim", "pybullet"), ("detector", "segmentation")])
def test_another_simulator_or_detector_plugin_is_refused(group, name):
    pytest.importorskip("pegame_pybullet")
    with pytest.raises(
        ConfigError, match=rf"Invalid value for '{group}' in a batched env: '{name}'"
    ):
        vector_env(2, overrides=[*BASE, f"{group}={name}"], opponent="random")


def test_paper_conditions_are_refused_for_their_turn_order_only():
    """The perception model's settings are played (tests/envs/test_vector.py); no env plays
    the paper's turns, a learner commanding before it sees the other's move."""
    with pytest.raises(ConfigError) as error:
        vector_env(2, overrides=[*BASE, "+experiment=paper_conditions"], opponent="random")
    assert str(error.value).startswith(
        "Invalid value for 'game.turn_order' in a batched env: 'evader_first'. "
    )


def test_several_settings_are_refused_in_one_paragraph():
    overrides = [*BASE, "game.turn_order=evader_first", "team.evaders=2"]
    with pytest.raises(ConfigError) as error:
        vector_env(2, overrides=overrides, opponent="random")
    message = str(error.value)
    assert message.startswith("Invalid values in a batched env: 'team.evaders': 2 (allowed: 1")
    assert "; 'game.turn_order': 'evader_first' (allowed:" in message and "\n" not in message
