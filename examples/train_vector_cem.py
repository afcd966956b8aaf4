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

The options are train_cem.py's (see there). The opponents are Python strategies playing
game by game (:mod:`pegame.vector.opponents`), so what the batch saves is the pursuer's
side of every step: the simulator, the detector, the observation.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from pegame.envs import vector_env
from pegame.envs.observations import ObservationSettings
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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=5.0, help="wall-time budget")
    parser.add_argument(
        "--generations", type=int, default=None, help="stop after this many (reproducible)"
    )
    parser.add_argument("--population", type=int, default=16, help="candidates per generation")
    parser.add_argument(
        "--elite", type=float, default=0.25, help="fraction of candidates refitted on"
    )
    parser.add_argument("--episodes", type=int, default=2, help="games per candidate and opponent")
    parser.add_argument("--t-max", type=float, default=30.0, help="game length in training (s)")
    parser.add_argument(
        "--opponents", default="random,smart", help="the evader strategies trained against"
    )
    parser.add_argument(
        "--override", action="append", default=["env=enclosed"], help="an app override"
    )
    parser.add_argument("--crop-cells", type=int, default=8)
    parser.add_argument("--crop-resolution", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="cem_pursuer.npz")
    args = parser.parse_args()

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
    n_obs = first.single_observation_space.shape[0]
    rng = np.random.default_rng(args.seed)
    # As train_cem.py: start near "do nothing", the crop's weights with a smaller spread.
    std = np.full((2, n_obs + 1), 1.0)
    std[:, first.layout["crop"]] = 0.03
    mean, std = np.zeros(std.size), std.ravel()
    n_elite = max(2, int(round(args.elite * args.population)))

    def policy_of(theta: np.ndarray) -> LinearPolicy:
        rows = theta.reshape(2, n_obs + 1)
        return LinearPolicy(rows[:, :-1], rows[:, -1], "pursuer", settings)

    deadline = time.monotonic() + 60.0 * args.minutes
    generation = 0
    while time.monotonic() < deadline and generation != args.generations:
        seeds = [int(s) for s in rng.integers(2**31, size=args.episodes)]
        thetas = mean + std * rng.standard_normal((args.population, mean.size))
        scores = evaluate(envs, [policy_of(theta) for theta in thetas], seeds)
        elite = thetas[np.argsort(scores)[-n_elite:]]
        mean, std = elite.mean(axis=0), elite.std(axis=0) + 0.02
        generation += 1
        print(
            f"generation {generation}: best {scores.max():.3f}, mean {scores.mean():.3f}, "
            f"elite mean {np.sort(scores)[-n_elite:].mean():.3f}",
            flush=True,
        )
    policy_of(mean).save(args.out)
    held_out = evaluate(envs_of(5), [policy_of(mean)], list(range(1000, 1005)))[0]
    print(
        f"saved {args.out}: tracking rate {held_out:.3f} over 5 held-out {args.t_max:g} s games "
        f"against each of the {args.opponents} evaders"
    )


if __name__ == "__main__":
    main()
