"""Train a linear pursuer with the cross-entropy method on the batched env: the training
of ``examples/train_cem.py``, with every game of a generation played in one batch.

Why this trainer: the CEM trainer is the house trainer (numpy only, no deep-learning
stack), it already writes the ``.npz`` that the ``policy`` pursuer plays, and its
generations are embarrassingly parallel: every candidate plays the same games. Here a
generation is one batched env per opponent (:func:`pegame.envs.vector_env`) with
``population x episodes`` games, game ``c * episodes + e`` played by candidate ``c`` with
the generation's seed ``e``. The batched games are the single env's games with the same
seeds, and the random draws and the scoring are train_cem.py's, so with the same
arguments both scripts train the same policy, bit for bit, this one in less wall time:

    python examples/train_vector_cem.py --minutes 5 --out cem_pursuer.npz
    python -m pegame pursuer=policy pursuer.path=cem_pursuer.npz evader=smart

The options and the CEM loop are train_cem.py's (imported from it). The opponents are Python strategies playing
game by game (:mod:`pegame.vector.opponents`), so what the batch saves is the pursuer's
side of every step: the simulator, the detector, the observation.
"""

from __future__ import annotations

import numpy as np
from train_cem import options, train  # the options and the CEM loop, shared

from pegame.envs import vector_env
from pegame.observe.observations import ObservationSettings
from pegame.policies import LinearPolicy


def evaluate(envs: dict, policies: list[LinearPolicy], seeds: list[int]) -> np.ndarray:
    """Each policy's mean tracking rate (0..1) over one game per opponent and seed, as
    train_cem.evaluate scores one policy (the same games, the same order of the mean).
    ``envs``: opponent -> its batched env of len(policies) * len(seeds) games."""
    rates = np.zeros((len(policies), len(envs), len(seeds)))
    owner = np.repeat(np.arange(len(policies)), len(seeds))
    weights = np.stack([policy.weights for policy in policies])[owner]
    bias = np.stack([policy.bias for policy in policies])[owner]
    for k, env in enumerate(envs.values()):
        obs, _ = env.reset(seed=[seed for _ in policies for seed in seeds])
        done = np.zeros(env.num_envs, np.bool_)
        while not done.all():
            # LinearPolicy.__call__ of every game's candidate at once: a stack of the same
            # matrix-vector products (tests/test_vector_train.py holds it to the same bits).
            scores = np.matmul(weights, obs.astype(np.float64)[:, :, None])[:, :, 0]
            actions = np.tanh(scores + bias).astype(np.float32)
            obs, _, terminated, truncated, info = env.step(actions)
            done = terminated | truncated
        rates[:, k, :] = info["tracking_rate"].reshape(len(policies), len(seeds))
    return np.array([np.mean(rates[c].ravel().tolist()) for c in range(len(policies))])


def main() -> None:
    args = options(__doc__)
    settings = ObservationSettings(args.crop_cells, args.crop_resolution)

    def envs_of(num_envs: int) -> dict:
        return {
            opponent: vector_env(
                num_envs,
                overrides=[*args.override, f"game.t_max={args.t_max}"],
                opponent=opponent,
                crop_cells=settings.crop_cells,
                crop_resolution=settings.crop_resolution,
            )
            for opponent in args.opponents.split(",")
        }

    envs = envs_of(args.population * args.episodes)
    first = next(iter(envs.values()))
    train(
        args,
        settings,
        first.single_observation_space.shape[0],
        first.layout["crop"],
        lambda policies, seeds: evaluate(envs, policies, seeds),
        lambda policy: evaluate(envs_of(5), [policy], list(range(1000, 1005)))[0],
    )


if __name__ == "__main__":
    main()
