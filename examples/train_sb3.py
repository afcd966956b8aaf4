"""Train a pursuer on ``pegame/Pursuit-v0`` with Stable-Baselines3's PPO, and evaluate it.

    pip install torch==2.13.0 --index-url https://download.pytorch.org/whl/cpu   # a CPU build
    pip install -e ".[sb3]"
    python examples/train_sb3.py --steps 200000 --out ppo_pursuer.zip

The env is the single-agent Gymnasium env with no glue: PPO's MlpPolicy on the flat
observation (pose, last detection, egocentric crop), actions (v, w) in [-1, 1], reward +1
per tick with the evader detected. After training, the policy (deterministic) and the
random and smart pursuers play ``--eval-seeds`` games against the same opponent on the
same seeds, and the mean tracking rates are printed. Torch comes from PyPI as a CUDA
build of several GB unless the CPU build is installed first (the first command), which is
why SB3 is an optional extra (``pegame[sb3]``) and not part of CI's install.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import gymnasium
import numpy as np

import pegame.envs  # noqa: F401  (registers pegame/Pursuit-v0)


def tracking_rate(
    env: gymnasium.Env, act: Callable[[np.ndarray], np.ndarray], seeds: list[int]
) -> float:
    """Mean tracking rate (0..1) of ``act(obs) -> action`` over one game per seed."""
    rates = []
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        done = False
        while not done:
            obs, _, terminated, truncated, info = env.step(act(obs))
            done = terminated or truncated
        rates.append(info["tracking_rate"])
    return float(np.mean(rates))


def strategy_rate(overrides: list[str], pursuer: str, opponent: str, seeds: list[int]) -> float:
    """Mean tracking rate of the strategy ``pursuer`` on the same games (pegame's own loop)."""
    from pegame.config import compose
    from pegame.game import Game

    rates = [
        Game(compose([*overrides, f"pursuer={pursuer}", f"evader={opponent}", f"game.seed={s}"]))
        .play("unused")
        .result["tracking_rate"]
        for s in seeds
    ]
    return float(np.mean(rates))


def main() -> None:
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    torch.set_num_threads(1)  # a small MLP: threads only contend with the envs

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200_000, help="PPO timesteps")
    parser.add_argument("--opponent", default="random", help="the evader strategy")
    parser.add_argument("--envs", type=int, default=4, help="parallel envs for PPO")
    parser.add_argument("--eval-seeds", type=int, default=20, help="games in the evaluation")
    parser.add_argument("--seed", type=int, default=0, help="PPO's seed")
    parser.add_argument("--out", default="ppo_pursuer.zip", help="where the model is saved")
    parser.add_argument(
        "--override", action="append", default=["env=enclosed", "game.t_max=30", "recorder=none"]
    )
    args = parser.parse_args()
    kwargs = {"overrides": args.override, "opponent": args.opponent}
    vec = make_vec_env("pegame/Pursuit-v0", n_envs=args.envs, seed=args.seed, env_kwargs=kwargs)
    model = PPO("MlpPolicy", vec, seed=args.seed, verbose=0)
    start = time.perf_counter()
    model.learn(total_timesteps=args.steps)
    print(f"trained {args.steps} steps in {time.perf_counter() - start:.0f} s -> {args.out}")
    model.save(args.out)
    env = gymnasium.make("pegame/Pursuit-v0", **kwargs)
    seeds = list(range(1000, 1000 + args.eval_seeds))  # games PPO never trained on
    learned = tracking_rate(env, lambda obs: model.predict(obs, deterministic=True)[0], seeds)
    print(f"PPO pursuer vs {args.opponent}: tracking rate {learned:.1%} over {len(seeds)} games")
    for pursuer in ("random", "smart"):
        rate = strategy_rate(args.override, pursuer, args.opponent, seeds)
        print(f"{pursuer} pursuer vs {args.opponent}: tracking rate {rate:.1%} on the same seeds")


if __name__ == "__main__":
    main()
