"""The plugin interfaces of pegame.api."""

from __future__ import annotations

import pytest

from pegame.api import Estimator, Pursuer
from pegame.config import compose
from pegame.game import Game


def test_narrow_tells_a_plugin_of_the_interfaces_kind_from_any_other():
    plugins = Game(compose(["recorder=none", "game.t_max=2"])).plugins
    assert Pursuer.narrow(plugins.pursuer) is plugins.pursuer
    with pytest.raises(TypeError, match="SmartEvader is not an instance of Pursuer"):
        Pursuer.narrow(plugins.evader)
    with pytest.raises(TypeError, match="GridSimulator is not an instance of Estimator"):
        Estimator.narrow(plugins.sim)
