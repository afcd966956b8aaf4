"""The value types (pegame.types.value_type) behave as the plain frozen dataclasses they
replace: same signature, fields, defaults, __post_init__, equality, hash, pickling, and
assignment refused; only their __init__ is faster and they hold their fields in slots."""

from __future__ import annotations

import dataclasses
import inspect
import pickle

import numpy as np
import pytest

import pegame.api
import pegame.types
from pegame.errors import ConfigError
from pegame.types import Camera, Plan, Pose, SensorFrame, value_type

VALUE_TYPES = sorted(
    {
        cls
        for module in (pegame.types, pegame.api)
        for cls in vars(module).values()
        if isinstance(cls, type)
        and dataclasses.is_dataclass(cls)
        and cls.__dataclass_params__.frozen
        and cls.__module__ == module.__name__
    },
    key=lambda cls: cls.__name__,
)


def plain_twin(cls):
    """The plain frozen dataclass with ``cls``'s fields, defaults and equality."""
    fields = [
        (
            f.name,
            f.type,
            dataclasses.field(default=f.default)
            if f.default is not dataclasses.MISSING
            else dataclasses.field(default_factory=f.default_factory)
            if f.default_factory is not dataclasses.MISSING
            else dataclasses.field(),
        )
        for f in dataclasses.fields(cls)
    ]
    return dataclasses.make_dataclass(
        cls.__name__, fields, frozen=True, eq=cls.__dataclass_params__.eq
    )


def test_the_value_types_are_found():
    names = {cls.__name__ for cls in VALUE_TYPES}
    assert {"Pose", "Velocity", "SensorFrame", "Detection", "Belief", "Tick"} <= names
    assert {"PursuerObservation", "EvaderObservation"} <= names


@pytest.mark.parametrize("cls", VALUE_TYPES, ids=lambda cls: cls.__name__)
def test_same_signature_and_fields_as_a_plain_frozen_dataclass(cls):
    twin = plain_twin(cls)
    assert str(inspect.signature(cls)) == str(inspect.signature(twin))
    # Build both from the same arguments: a distinct object per required field.
    required = [
        f.name
        for f in dataclasses.fields(cls)
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    args = {name: object() for name in required}
    mine, theirs = cls(**args), twin(**args)
    for f in dataclasses.fields(cls):
        a, b = getattr(mine, f.name), getattr(theirs, f.name)
        if f.default_factory is dataclasses.MISSING:
            assert a is b
        else:
            assert type(a) is type(b)
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(mine, dataclasses.fields(cls)[0].name, 1)
    assert not hasattr(mine, "__dict__")  # slots: its fields only, read as slot loads
    with pytest.raises(dataclasses.FrozenInstanceError):
        delattr(mine, dataclasses.fields(cls)[0].name)


def test_positional_keyword_and_default_arguments():
    assert dataclasses.asdict(Pose(1.0, 2.0)) == {"x": 1.0, "y": 2.0, "theta": 0.0}
    assert Pose(1.0, y=2.0, theta=0.5) == Pose(1.0, 2.0, 0.5)
    with pytest.raises(TypeError):
        Pose(1.0)
    with pytest.raises(TypeError):
        Pose(1.0, 2.0, 0.0, 4.0)
    with pytest.raises(TypeError):
        Pose(1.0, 2.0, z=3.0)


def test_equality_hash_replace_and_pickling():
    pose = Pose(1.0, 2.0, 0.5)
    assert pose == Pose(1.0, 2.0, 0.5) and hash(pose) == hash(Pose(1.0, 2.0, 0.5))
    assert pose != Pose(1.0, 2.0, 0.6)
    assert dataclasses.replace(pose, theta=0.0) == Pose(1.0, 2.0, 0.0)
    assert pickle.loads(pickle.dumps(pose)) == pose
    frame = SensorFrame(time=0.1, camera_pose=pose, evader_truth=pose)
    assert frame != SensorFrame(time=0.1, camera_pose=pose, evader_truth=pose)  # eq=False
    assert pickle.loads(pickle.dumps(frame)).camera_pose == pose


def test_post_init_still_validates():
    with pytest.raises(ConfigError, match="camera.fov"):
        Camera(fov=-1.0)


def test_default_factories_keep_the_dataclass_init():
    a, b = Plan(), Plan()
    assert a.path is not b.path and a.info is not b.info
    assert a.path.shape == (0, 2)


def test_a_new_value_type():
    @value_type
    class Sample:
        a: int
        b: np.ndarray | None = None

    sample = Sample(3)
    assert (sample.a, sample.b) == (3, None) and sample == Sample(3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        sample.a = 4
