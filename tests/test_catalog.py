"""``python -m pegame.catalog``: the listing, and one plugin's parameters with their
defaults and comments read from its Config."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import pytest

from pegame import registry
from pegame.catalog import describe_plugin, field_comments, main, parameters


def test_every_field_of_every_registered_plugin_has_its_default_and_a_comment():
    for group in registry.GROUPS:
        for name in registry.available(group):
            config = registry.load(group, name).Config
            rows = parameters(group, name)
            assert [row[0] for row in rows] == [f.name for f in dataclasses.fields(config)]
            for field, _, _, comment in rows:
                assert comment, f"{group}/{name}: field {field} has no comment in its Config"


def test_a_plugins_parameters_are_its_config_defaults_with_units():
    text = describe_plugin("pursuer", "smart")
    line = next(row for row in text.splitlines() if row.split()[:1] == ["pursuer.standoff"])
    assert line.split()[1:3] == ["float", "1.5"]
    assert "m, distance to keep from the evader" in line
    assert "pursuer.radius" in text  # the role's body fields, inherited from Pursuer.Config


def test_comments_come_from_the_class_and_its_bases_wrapped_values_included():
    @dataclasses.dataclass
    class Base:
        a: float = 1.0  # m, the base's field

    @dataclasses.dataclass
    class Child(Base):
        b: float = 2.0  # s, a value the formatter wrapped
        c: int = 3

    assert field_comments(Child) == {
        "a": "m, the base's field",
        "b": "s, a value the formatter wrapped",
    }


@pytest.mark.parametrize(
    ("argument", "expected"),
    [
        (
            "pursuers/smart",
            "GROUP one of sim, detector, estimator, pursuer, evader, recorder. Did you mean 'pursuer'?",
        ),
        (
            "pursuer/smrt",
            "the pursuer plugins are anticipating, cooperative, policy, random, smart. Did you mean 'smart'?",
        ),
    ],
)
def test_an_unknown_group_or_name_is_one_line_naming_the_allowed_values(argument, expected, capsys):
    assert main([argument]) == 2
    err = capsys.readouterr().err
    assert expected in err and len(err.strip().splitlines()) == 1


def test_the_command_line_lists_the_plugins_and_one_plugins_parameters():
    listing = subprocess.run(
        [sys.executable, "-m", "pegame.catalog", "estimator/particle_filter"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert "estimator.n_particles" in listing and "number of particles N" in listing
