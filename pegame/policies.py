"""Learned policies as pegame strategies: loading them and playing them in a game.

A policy maps an observation vector of :mod:`pegame.observe.observations` (float32, the
env's layout) to an action of :mod:`pegame.observe.actions` (2 numbers (v, w) scaled to
[-1, 1]). It is given as

- ``"package.module:function"``: any callable ``f(obs) -> action`` (for example a
  wrapper around a Stable-Baselines3 model's ``predict``); the strategy's config gives
  its observation settings; or
- a ``.npz`` file of a :class:`LinearPolicy` (``examples/train_cem.py`` writes one),
  which also stores the role and the observation settings and decision period it was
  trained with.

:class:`PolicyStrategy` is the ``policy`` pursuer and evader (one strategy for both roles,
:func:`pegame.roles.for_role`); it plays through a :class:`PolicyPlayer`, which builds
the observation every control tick, exactly as the env does, asks the policy for a new
action every decision period, clips it to [-1, 1] (a NaN is an error) and
scales it to (v, w).
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from pegame.api import Context, EvaderObservation, PursuerObservation, Strategy
from pegame.errors import ConfigError, require
from pegame.observe.actions import to_velocity
from pegame.observe.observations import EvaderFeatures, ObservationSettings, PursuerFeatures
from pegame.observe.settings import EnvSettings
from pegame.types import Body, Plan, Pose, Velocity

#: version of the .npz layout written by save()
FORMAT = 1


@dataclass(frozen=True, eq=False)
class LinearPolicy:
    """action = tanh(weights @ obs + bias): weights (2, n), bias (2,), for ``role``
    ('pursuer' or 'evader') trained on observations of ``settings`` with actions held for
    ``decision_period`` s (None: one control tick)."""

    weights: np.ndarray
    bias: np.ndarray
    role: str
    settings: ObservationSettings
    decision_period: float | None = None

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return np.tanh(self.weights @ obs + self.bias)

    def save(self, path: str | Path) -> None:
        """Write the policy to ``path`` (.npz, no pickled objects)."""
        s = self.settings
        np.savez(
            path,
            format=FORMAT,
            weights=self.weights,
            bias=self.bias,
            role=self.role,
            crop_cells=s.crop_cells,
            crop_resolution=s.crop_resolution,
            belief=s.belief,
            decision_period=np.nan if self.decision_period is None else self.decision_period,
        )

    @classmethod
    def load(cls, path: str | Path) -> LinearPolicy:
        """Read a policy written by :meth:`save`; ConfigError naming the file if it is not one."""
        try:
            with np.load(path, allow_pickle=False) as data:
                if int(data["format"]) != FORMAT:
                    raise ValueError(f"format {int(data['format'])}, expected {FORMAT}")
                settings = ObservationSettings(
                    int(data["crop_cells"]), float(data["crop_resolution"]), bool(data["belief"])
                )
                period = float(data["decision_period"])
                policy = cls(
                    np.asarray(data["weights"], dtype=np.float64),
                    np.asarray(data["bias"], dtype=np.float64),
                    str(data["role"]),
                    settings,
                    None if math.isnan(period) else period,
                )
        except (OSError, KeyError, ValueError) as exc:
            raise ConfigError(f"Policy file {path}: not a pegame linear policy ({exc}).") from None
        if policy.weights.ndim != 2 or policy.weights.shape[0] != 2 or policy.bias.shape != (2,):
            raise ConfigError(
                f"Policy file {path}: weights must be (2, n) and bias (2,), got "
                f"{policy.weights.shape} and {policy.bias.shape}."
            )
        return policy


@dataclass
class PolicyOptions:
    """The ``policy`` strategies' parameters (on top of the role's body parameters)."""

    path: str = (
        ""  # a linear-policy .npz file, or "package.module:function" (a callable obs -> action)
    )
    crop_cells: int | None = None  # observation crop, cells per side; None: the .npz's, else 32
    crop_resolution: float | None = None  # m per crop cell; None: the .npz's, else 0.2
    belief: bool | None = (
        None  # observe the estimator's summary (pursuer); None: the .npz's, else false
    )
    decision_period: float | None = (
        None  # s an action is held; None: the .npz's, else one control tick
    )

    def check(self, role: str) -> None:
        """Range checks (keys relative to the node); an empty path is caught when the
        strategy is built."""
        require(
            self.path == "" or self.path.endswith(".npz") or ":" in self.path,
            "path",
            "a .npz policy file or 'package.module:function'",
            self.path,
        )
        require(
            role == "pursuer" or not self.belief,
            "belief",
            "null or false (only the pursuer has a belief)",
            self.belief,
        )
        require(
            self.crop_cells is None or self.crop_cells >= 1,
            "crop_cells",
            "a whole number >= 1, or null",
            self.crop_cells,
        )
        for key in ("crop_resolution", "decision_period"):
            value = getattr(self, key)
            require(
                value is None or (value > 0 and math.isfinite(value)),
                key,
                "a positive number, or null",
                value,
            )


def load_policy(
    path: str, role: str, base_dir: str | Path | None = None
) -> Callable[[np.ndarray], Any]:
    """The policy named by ``path`` (see the module docstring): a LinearPolicy for a .npz
    (relative paths from ``base_dir``, default the working directory), else the callable
    at ``module:attribute``. ConfigError naming ``role.path`` when it cannot be loaded."""
    if path.endswith(".npz"):
        file = Path(path).expanduser()
        if not file.is_absolute():
            file = Path(base_dir or Path.cwd()) / file
        if not file.is_file():
            raise ConfigError(
                f"Invalid value for '{role}.path': policy file {file} does not exist."
            )
        policy = LinearPolicy.load(file)
        if policy.role != role:
            raise ConfigError(
                f"Invalid value for '{role}.path': {file} is a policy for the {policy.role}."
            )
        return policy
    module_name, _, attribute = path.partition(":")
    try:
        target: Any = importlib.import_module(module_name)
        for part in attribute.split("."):
            target = getattr(target, part)
    except (ImportError, AttributeError) as exc:
        raise ConfigError(
            f"Invalid value for '{role}.path': cannot load {path!r} ({exc})."
        ) from None
    if not callable(target):
        raise ConfigError(f"Invalid value for '{role}.path': {path!r} is not callable.")
    return target


class PolicyPlayer:
    """Plays a policy for ``role`` in a game: see the module docstring."""

    def __init__(self, options: PolicyOptions, role: str, context: Context) -> None:
        if not options.path:
            raise ConfigError(
                f"Missing value for '{role}.path': give {role}.path=<policy.npz> or "
                f"{role}.path=<package.module:function>."
            )
        self.policy = load_policy(options.path, role)
        trained = self.policy if isinstance(self.policy, LinearPolicy) else None
        # The strategy's option wins, then what the policy was trained with, then the env default.
        stored = (
            {}
            if trained is None
            else {**asdict(trained.settings), "decision_period": trained.decision_period}
        )
        picked = {
            key: value if value is not None else stored.get(key, getattr(EnvSettings, key))
            for key, value in ((f.name, getattr(options, f.name)) for f in fields(PolicyOptions))
            if key != "path"
        }
        settings = EnvSettings(**picked)
        features = PursuerFeatures if role == "pursuer" else EvaderFeatures
        self.features = features(context, settings.observation)
        if trained is not None and trained.weights.shape[1] != self.features.size:
            raise ConfigError(
                f"Invalid value for '{role}.path': the policy expects {trained.weights.shape[1]} observation "
                f"values, the observation settings give {self.features.size}."
            )
        self.every = settings.ticks_per_action(context.control_dt)
        self.body: Body = getattr(context, role)
        self.role = role
        self.reset()

    def reset(self) -> None:
        """A new game."""
        self.features.reset()
        self.tick = 0
        self.command = Velocity()

    def plan(self) -> Plan:
        """The strategy's plan: none (a policy commands velocities directly)."""
        return Plan(info={"command": (self.command.v, self.command.w)})

    def control(self, observation: Any) -> Velocity:
        """The command for this control tick from the role's ``observation`` (a
        PursuerObservation or an EvaderObservation, as this role's features take it)."""
        self.features.update(observation)
        if self.tick % self.every == 0:
            action = self.policy(self.features(observation))
            self.command = to_velocity(
                action, self.body, clip=True, who=f"the {self.role} policy's action"
            )
        self.tick += 1
        return self.command


class PolicyStrategy(Strategy[PursuerObservation | EvaderObservation]):
    """A trained policy (linear .npz or a callable) on its role's env observation; it
    commands velocities directly and makes no plan."""

    description = (
        "A learned policy (linear .npz or module:function) on the pegame.observe observation."
    )
    #: 'pursuer' or 'evader', set by :func:`pegame.roles.for_role`
    role: str

    def __init__(self, config: Any, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.player = PolicyPlayer(config, self.role, context)

    def reset(self, pose: Pose) -> None:
        self.player.reset()

    def decide(self, observation: PursuerObservation | EvaderObservation) -> Plan:
        return self.player.plan()

    def control(self, observation: PursuerObservation | EvaderObservation) -> Velocity:
        return self.player.control(observation)
