"""Train a linear pursuer on ``pegame/Pursuit-v0`` with the cross-entropy method (numpy only).

The policy is action = tanh(W obs + b) (:class:`pegame.policies.LinearPolicy`). Each
generation draws ``--population`` parameter vectors from a diagonal Gaussian, scores
each by its mean tracking rate over ``--episodes`` games against each opponent (the same
seeds for every candidate of a generation, so that they are compared on the same
games), and refits the Gaussian to the best ``--elite`` fraction. The mean of the final
Gaussian is saved as an ``.npz`` that the ``policy`` pursuer plays:

    python examples/train_cem.py --minutes 5 --out cem_pursuer.npz
    python -m pegame pursuer=policy pursuer.path=cem_pursuer.npz evader=smart

It trains against both the random and the smart evader by default (trained against one
only, the policy does poorly against the other). A small crop (8 x 8 cells of 0.5 m)
keeps the search space small (146 parameters). Later app overrides win, e.g.
``--override env=hall --override detector.miss_probability=0.1``. The shipped
``examples/cem_pursuer.npz`` was trained with the defaults and ``--generations 132``
(about 7 minutes on a busy 2-core machine).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import gymnasium
import numpy as np

import pegame.envs  # noqa: F401  (registers pegame/Pursuit-v0)
from pegame.observe.observations import ObservationSettings
from pegame.policies import LinearPolicy


def evaluate(envs: list[gymnasium.Env], policy: LinearPolicy, seeds: list[int]) -> float:
    """Mean tracking rate (0..1) of ``policy`` over one game per env and seed."""
    rates = []
    for env in envs:
        for seed in seeds:
            obs, _ = env.reset(seed=seed)
            done = False
            while not done:
                obs, _, terminated, truncated, info = env.step(policy(obs).astype(np.float32))
                done = terminated or truncated
            rates.append(info["tracking_rate"])
    return float(np.mean(rates))


def options(description: str) -> argparse.Namespace:
    """The trainer's command-line options (shared with ``train_vector_cem.py``)."""
    parser = argparse.ArgumentParser(description=description.splitlines()[0])
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
    return parser.parse_args()


def train(
    args: argparse.Namespace,
    settings: ObservationSettings,
    n_obs: int,
    crop: slice,
    score: Callable[[list[LinearPolicy], list[int]], np.ndarray],
    held_out: Callable[[LinearPolicy], float],
) -> None:
    """The cross-entropy method (module docstring) over linear policies of ``n_obs``
    observations whose ``crop`` part starts with a smaller spread; ``score(policies,
    seeds)`` gives each policy's mean tracking rate, ``held_out(policy)`` the final
    policy's on held-out games. Saves the policy to ``args.out``."""
    rng = np.random.default_rng(args.seed)
    # Start near "do nothing"; the crop's many weights start with a smaller spread than
    # the pose and detection features so that they do not drown the useful signal.
    std = np.full((2, n_obs + 1), 1.0)
    std[:, crop] = 0.03
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
        scores = score([policy_of(theta) for theta in thetas], seeds)
        elite = thetas[np.argsort(scores)[-n_elite:]]
        # A small floor on the spread keeps the search from collapsing too early.
        mean, std = elite.mean(axis=0), elite.std(axis=0) + 0.02
        generation += 1
        print(
            f"generation {generation}: best {scores.max():.3f}, mean {scores.mean():.3f}, "
            f"elite mean {np.sort(scores)[-n_elite:].mean():.3f}",
            flush=True,
        )
    policy_of(mean).save(args.out)
    print(
        f"saved {args.out}: tracking rate {held_out(policy_of(mean)):.3f} over 5 held-out "
        f"{args.t_max:g} s games against each of the {args.opponents} evaders"
    )


def main() -> None:
    args = options(__doc__)
    settings = ObservationSettings(args.crop_cells, args.crop_resolution)
    envs = [
        gymnasium.make(
            "pegame/Pursuit-v0",
            overrides=[*args.override, f"game.t_max={args.t_max}"],
            opponent=opponent,
            crop_cells=settings.crop_cells,
            crop_resolution=settings.crop_resolution,
        )
        for opponent in args.opponents.split(",")
    ]
    train(
        args,
        settings,
        envs[0].observation_space.shape[0],
        envs[0].unwrapped.layout["crop"],
        lambda policies, seeds: np.array([evaluate(envs, p, seeds) for p in policies]),
        lambda policy: evaluate(envs, policy, list(range(1000, 1005))),
    )


if __name__ == "__main__":
    main()
