"""The plugin distributions' config files follow "one name everywhere": file stem, entry
point and ``name:`` agree, the file's values are valid for the plugin, and Hydra finds
them through the pegame.configs entry point."""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

import pytest

from pegame import registry
from pegame.config import compose

PLUGINS = [
    ("pybullet", "pegame_pybullet", "pegame-pybullet", [("sim", "pybullet"), ("detector", "segmentation")]),
    ("cv2", "pegame_vision", "pegame-vision", [("detector", "vision")]),
]


@pytest.mark.parametrize(("dependency", "package", "distribution", "options"), PLUGINS)
def test_config_files_match_their_entry_points(dependency, package, distribution, options):
    pytest.importorskip(dependency)
    conf = Path(str(files(f"{package}.conf")))
    assert sorted((p.parent.name, p.stem) for p in conf.glob("*/*.yaml")) == sorted(options)
    for group, name in options:
        assert registry.distribution_of(registry.entry_point(group, name)) == distribution
        cfg = compose([f"{group}={name}"])
        assert cfg[group].name == name
        cls = registry.load(group, name)
        config = registry.make_config(group, cls, {k: v for k, v in cfg[group].items() if k != "name"})
        assert config == cls.Config()  # the file documents the defaults
