"""The environments' speed: steps per second of the PettingZoo env with random actions,
and of the batched env against it in the same run. The env packages are imported on
first use, so that ``python -m pegame.bench`` formats its report without them."""

from __future__ import annotations

import gc
import math
import os
import statistics
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover - typing only (imported where used)
    from pegame.envs.vector import EvasionVectorEnv, PursuitVectorEnv


def bench_steps_per_second(
    seconds: float = 5.0,
    overrides: Sequence[str] = ("env=enclosed",),
    seed: int = 0,
    **settings: Any,
) -> dict[str, float]:
    """Run the two-agent env with uniformly random actions for about ``seconds`` s of
    wall time on one core (default options, a paper map) and measure it.

    Returns ``steps_per_s`` (step() calls per second, resets excluded), ``reset_ms``
    (mean reset time: spawn and plugin resets) and ``steps_per_s_with_resets``. The first
    reset and step (numba compilation or cache loading) are not timed.
    """
    from pegame.envs.parallel import parallel_env

    env = parallel_env(overrides=overrides, **settings)
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    env.step({agent: np.zeros(2, np.float32) for agent in env.possible_agents})
    stepping = resetting = 0.0
    steps = resets = 0
    while stepping + resetting < seconds:
        start = time.perf_counter()
        env.reset(seed=seed + resets)
        resetting += time.perf_counter() - start
        resets += 1
        actions = rng.uniform(-1.0, 1.0, (env.game.steps, 2, 2)).astype(np.float32)
        start = time.perf_counter()
        for pair in actions:
            env.step({"pursuer": pair[0], "evader": pair[1]})
            if not env.agents:
                break
        stepping += time.perf_counter() - start
        steps += len(actions)
    env.close()
    return {
        "steps_per_s": steps / stepping,
        "reset_ms": 1e3 * resetting / resets,
        "steps_per_s_with_resets": steps / (stepping + resetting),
    }


def _rss_bytes() -> int:
    """This process's resident memory (bytes; Linux /proc, else 0)."""
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError):
        return 0


def _array_bytes(env: PursuitVectorEnv | EvasionVectorEnv) -> int:
    """Bytes of a batched env's arrays: its games' state, the opponent's action table and
    one batch of observations."""
    game = env.game
    table = getattr(game.opponent, "table", None)
    observation = game.num_games * game.features[env.role].size * 4
    return sum(a.nbytes for a in game.state) + (0 if table is None else table.nbytes) + observation


def _vector_steps_per_second(
    env: PursuitVectorEnv | EvasionVectorEnv, actions: np.ndarray, threads: int
) -> float:
    """Env steps (games x batched steps) per second of ``env`` over the batched
    ``actions`` (steps, N, 2), on ``threads`` numba threads, no game ending on the way."""
    import numba

    numba.set_num_threads(threads)
    start = time.perf_counter()
    for batch in actions:
        env.step(batch)
    return actions.shape[0] * env.num_envs / (time.perf_counter() - start)


#: rounds of the batched env timed before any other batched env exists in the process,
#: and as many after they are deleted
ALONE_ROUNDS = 5
#: untimed rounds before those: without them the env read 1.17x and 1.19x faster beside
#: the others than alone (two runs, AMD EPYC), with them 1.08x
WARM_ROUNDS = 3

#: the paper's conditions as a batched env plays them (no env plays the paper's turns)
PAPER_CONDITIONS = ("+experiment=paper_conditions", "game.turn_order=simultaneous")


class _DecisionPeriods:
    """Rounds of a batched env against a strategy opponent, each of the fewest env steps
    that hold whole decision periods of the opponent (lcm(decide_every, ticks per step)
    control ticks), a game that would end inside one reset first, untimed; ``env`` is
    reset with ``seed`` and stepped once (its opponent's first calls, untimed)."""

    def __init__(self, env: PursuitVectorEnv | EvasionVectorEnv, seed: int) -> None:
        game = env.game
        env.reset(seed=seed)
        env.step(np.zeros((env.num_envs, 2), np.float32))  # the opponent's first calls
        self.env, self.seed, self.games, self.played = env, seed, 1, 1
        self.steps = math.lcm(game.rules.decide_every, game.ticks_per_action)
        self.steps //= game.ticks_per_action

    def steps_per_second(self, rng: np.random.Generator) -> float:
        """One round's env steps (games x batched steps) per second, on one thread."""
        env = self.env
        if self.played + self.steps >= env.game.steps:
            env.reset(seed=self.seed + self.games * env.num_envs)
            self.played, self.games = 0, self.games + 1
        actions = rng.uniform(-1.0, 1.0, (self.steps, env.num_envs, 2)).astype(np.float32)
        self.played += self.steps
        return _vector_steps_per_second(env, actions, 1)


def bench_vector_env(
    seconds: float = 20.0,
    num_envs: int = 4096,
    smart_envs: int = 1024,
    overrides: Sequence[str] = ("env=enclosed",),
    seed: int = 0,
    single_steps: int = 300,
    scaling_base: int = 1024,
    **settings: Any,
) -> dict[str, float | int]:
    """The batched env (:mod:`pegame.envs.vector`) against the single env, in the same run.

    Rounds alternate (so that the machine's other load hits all alike): the two-agent
    single env's steps with random actions (``single_steps`` of them, as
    :func:`bench_steps_per_second`), the
    batched pursuer env of ``num_envs`` games against the random evader with
    ``model=action`` on one numba thread (the per-core figure, as NUMBA_NUM_THREADS=1)
    and on all of numba's threads, and the batched env of ``smart_envs`` games against
    the smart evader, under the default and under the paper's conditions
    (:data:`PAPER_CONDITIONS`), over whole decision periods (the env steps holding a whole
    number of the evader's decision intervals: 10 at the defaults, the smart evader
    deciding every 10th tick; a shorter round mostly holds no decision and overstates the
    rate; a game that would end inside a round is reset first, untimed). Resets are not timed (a reset
    spawns each game in Python: its cost per game is ``vector_reset_ms_per_game``).
    Figures are medians over the rounds; ``vector_speedup_per_core`` is the median of the
    rounds' ratios to the single env. ``vector_beside_others_ratio``: the batched env's
    one-core rate in those rounds (the smart opponents' envs alive beside it) over its rate
    in ALONE_ROUNDS rounds before they were built (after WARM_ROUNDS untimed ones) and
    ALONE_ROUNDS after they were deleted (so that the env's drift over the run falls on
    both sides); ``vector_scaling_over_smaller``: its rate
    over the rate of an env of ``scaling_base`` games (``num_envs_smaller``, 1024) in the
    same rounds (None at that many games or fewer).
    ``settings``: env options (:class:`pegame.observe.settings.EnvSettings`) for both.
    Memory per game: the resident memory the batched env added (its kernels already
    loaded), divided by the games; and the bytes of its arrays per game (state, opponent
    table, one observation).
    """
    import numba

    from pegame.envs.parallel import parallel_env
    from pegame.envs.vector import vector_env
    from pegame.vector.state import PARALLEL_GAMES

    rng = np.random.default_rng(seed)
    threads = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets its options at import, its stubs have none
    single = parallel_env(overrides=overrides, **settings)
    single.reset(seed=seed)
    single.step({agent: np.zeros(2, np.float32) for agent in single.possible_agents})
    random_evader = [*overrides, "evader.model=action"]
    # Load the kernels (the parallel ones from PARALLEL_GAMES games on) before measuring.
    size = min(num_envs, PARALLEL_GAMES)
    warm = vector_env(size, overrides=random_evader, opponent="random", **settings)
    warm.reset(seed=seed)
    warm.step(np.zeros((size, 2), np.float32))
    before = _rss_bytes()
    env = vector_env(num_envs, overrides=random_evader, opponent="random", **settings)
    start = time.perf_counter()
    env.reset(seed=seed)
    reset_s = time.perf_counter() - start
    env.step(np.zeros((num_envs, 2), np.float32))
    memory = (_rss_bytes() - before) / num_envs
    arrays = _array_bytes(env) / num_envs
    batch = 4
    for _ in range(WARM_ROUNDS):  # untimed: the first rounds touch the state's pages
        _vector_steps_per_second(env, np.zeros((batch, num_envs, 2), np.float32), 1)
    played = 1 + (WARM_ROUNDS + ALONE_ROUNDS) * batch
    alone = [
        _vector_steps_per_second(
            env, rng.uniform(-1.0, 1.0, (batch, num_envs, 2)).astype(np.float32), 1
        )
        for _ in range(ALONE_ROUNDS)
    ]
    smaller = None
    if num_envs > scaling_base:
        smaller = vector_env(scaling_base, overrides=random_evader, opponent="random", **settings)
        smaller.reset(seed=seed)
        smaller.step(np.zeros((scaling_base, 2), np.float32))
    smart = {
        key: _DecisionPeriods(
            vector_env(smart_envs, overrides=options, opponent="smart", **settings), seed
        )
        for key, options in (
            ("smart", overrides),
            ("smart_paper", [*overrides, *PAPER_CONDITIONS]),
        )
    }
    per_round: dict[str, list[float]] = {"single": [], "core": [], "all": [], "smaller": []}
    per_round.update({key: [] for key in smart})
    deadline = time.perf_counter() + seconds
    after = ALONE_ROUNDS * batch  # the steps the alone rounds after the others need
    while time.perf_counter() < deadline and played + 3 * batch + after < env.game.steps:
        single.reset(seed=seed + played)
        pairs = rng.uniform(-1.0, 1.0, (single_steps, 2, 2)).astype(np.float32)
        start = time.perf_counter()
        for pair in pairs:
            single.step({"pursuer": pair[0], "evader": pair[1]})
        per_round["single"].append(len(pairs) / (time.perf_counter() - start))
        actions = rng.uniform(-1.0, 1.0, (batch, num_envs, 2)).astype(np.float32)
        per_round["core"].append(_vector_steps_per_second(env, actions, 1))
        per_round["all"].append(_vector_steps_per_second(env, actions, threads))
        if smaller is not None:
            fewer = actions[:, :scaling_base]
            per_round["smaller"].append(_vector_steps_per_second(smaller, fewer, 1))
        for key, periods in smart.items():
            per_round[key].append(periods.steps_per_second(rng))
        played += 3 * batch
    del smart, smaller  # the other envs gone, the env alone again, at the end as at the start
    gc.collect()
    alone += [
        _vector_steps_per_second(
            env, rng.uniform(-1.0, 1.0, (batch, num_envs, 2)).astype(np.float32), 1
        )
        for _ in range(ALONE_ROUNDS)
    ]
    numba.set_num_threads(threads)
    single.close()
    median = {key: statistics.median(values) for key, values in per_round.items() if values}
    ratios = [v / s for v, s in zip(per_round["core"], per_round["single"])]
    return {
        "num_envs": num_envs,
        "numba_threads": threads,
        "rounds": len(ratios),
        "single_env_steps_per_s": median["single"],
        "vector_env_steps_per_s": median["core"],
        "vector_env_steps_per_s_all_cores": median["all"],
        "vector_speedup_per_core": statistics.median(ratios),
        "vector_env_steps_per_s_alone": statistics.median(alone),
        "vector_beside_others_ratio": median["core"] / statistics.median(alone),
        "num_envs_smaller": scaling_base,
        "vector_scaling_over_smaller": (
            median["core"] / median["smaller"] if "smaller" in median else None
        ),
        "vector_reset_ms_per_game": 1e3 * reset_s / num_envs,
        "vector_env_bytes_per_game": memory,
        "vector_env_array_bytes_per_game": arrays,
        "num_envs_smart": smart_envs,
        "vector_env_steps_per_s_smart": median["smart"],
        "vector_env_steps_per_s_smart_paper": median["smart_paper"],
        "smart_opponent_us_per_game_step": 1e6 / median["smart"] - 1e6 / median["core"],
    }


def vector_env_figures(quick: bool) -> dict:
    """:func:`bench_vector_env` for ``python -m pegame.bench`` (``quick``: 1024 games,
    5 s); empty without gymnasium."""
    try:
        import gymnasium  # noqa: F401
    except ImportError:
        return {}
    return bench_vector_env(seconds=5.0 if quick else 20.0, num_envs=1024 if quick else 4096)


def format_vector(report: dict) -> str:
    """The batched env's line of ``python -m pegame.bench``'s text report."""
    if report.get("vector_env_steps_per_s") is None:
        return "batched env: -"
    r = report
    scaling = r.get("vector_scaling_over_smaller")
    beside = f"beside other batched envs {r['vector_beside_others_ratio']:.2f}x its rate alone"
    if scaling is not None:
        beside += f", {scaling:.2f}x the rate of {r['num_envs_smaller']} games"
    return (
        f"batched env ({r['num_envs']} games, random evader): {r['vector_env_steps_per_s']:.0f} "
        f"steps/s on one core ({r['vector_speedup_per_core']:.1f}x the single env's "
        f"{r['single_env_steps_per_s']:.0f} in the same rounds), "
        f"{r['vector_env_steps_per_s_all_cores']:.0f} on {r['numba_threads']} threads "
        f"({beside}); "
        f"{r['vector_env_bytes_per_game'] / 1024:.1f} KiB per game "
        f"({r['vector_env_array_bytes_per_game'] / 1024:.1f} KiB of arrays), reset "
        f"{r['vector_reset_ms_per_game']:.2f} ms per game; smart evader "
        f"({r['num_envs_smart']} games): {r['vector_env_steps_per_s_smart']:.0f} steps/s, "
        f"+{r['smart_opponent_us_per_game_step']:.1f} us per game step, under the paper's "
        f"conditions {r['vector_env_steps_per_s_smart_paper']:.0f} steps/s"
    )
