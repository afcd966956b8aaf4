"""Reference games: every built-in plugin played on fixed seeds, their measures stored.

``python -m pegame.testing.reference_games`` (from a checkout) plays them and writes
``tests/data/reference_games.json``; ``tests/test_reference_games.py`` plays them again and
requires the same measures, so a refactoring that changes a game fails. Regenerate only for
a change that is meant to change games, and say so in its commit. The cases need the
checkout's ``examples/`` (a trained policy) and the pybullet and vision plugins.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

#: the checkout this module sits in (pegame/testing/ -> the repository root)
CHECKOUT = Path(__file__).resolve().parents[2]
EXAMPLES = CHECKOUT / "examples"
DATA = CHECKOUT / "tests" / "data" / "reference_games.json"

SHORT = ["game.t_max=20", "recorder=none"]

#: (label, overrides); each is played with seeds SEEDS
CASES = [
    ("S-S enclosed", ["env=enclosed", "pursuer=smart", "evader=smart"]),
    ("S-S brick ratio 0.5", ["env=brick", "pursuer=smart", "evader=smart", "game.speed_ratio=0.5"]),
    ("S-R hall ratio 2", ["env=hall", "pursuer=smart", "evader=random", "game.speed_ratio=2"]),
    ("R-R enclosed", ["env=enclosed", "pursuer=random", "evader=random"]),
    ("R-S brick", ["env=brick", "pursuer=random", "evader=smart"]),
    ("S-S kalman", ["env=enclosed", "estimator=kalman"]),
    ("S-S last_seen", ["env=brick", "estimator=last_seen"]),
    ("S-S stratified", ["env=enclosed", "estimator.resampler=stratified"]),
    ("S-S residual", ["env=hall", "estimator.resampler=residual"]),
    ("S-S multinomial", ["env=brick", "estimator.resampler=multinomial"]),
    (
        "policy-S",
        ["env=enclosed", "pursuer=policy", f"pursuer.path={EXAMPLES / 'cem_pursuer.npz'}"],
    ),
    ("S-S decision 2 Hz", ["env=enclosed", "game.decision_hz=2"]),
    ("S-S pybullet segmentation", ["sim=pybullet", "detector=segmentation", "game.t_max=6"]),
    ("S-R pybullet vision", ["sim=pybullet", "detector=vision", "evader=random", "game.t_max=6"]),
]
SEEDS = (0, 1)


def play(overrides: list[str], seed: int) -> dict:
    """The result of one game (no files written)."""
    from pegame.config import compose
    from pegame.game import Game

    cfg = compose([*SHORT, *overrides, f"game.seed={seed}"])
    return Game(cfg).play("unused").result


def belief_digest() -> str:
    """sha256 of every tick's particles and weights in a short S-S game: far more sensitive
    than the measures, which ulp-level differences rarely reach."""
    import hashlib

    from pegame.config import compose
    from pegame.game import Game

    loop = Game(compose(["game.t_max=10", "recorder=none", "env=brick"])).start()
    digest = hashlib.sha256()
    while not loop.done:
        loop.advance()
        particles, weights = loop.belief.particles, loop.belief.weights
        if particles is None or weights is None:
            raise RuntimeError("The digest needs the particle filter's particles and weights.")
        digest.update(particles.tobytes())
        digest.update(weights.tobytes())
    return digest.hexdigest()


def main() -> int:
    games = [
        {"label": label, "overrides": overrides, "seed": seed, "result": play(overrides, seed)}
        for label, overrides in CASES
        for seed in SEEDS
    ]
    DATA.parent.mkdir(exist_ok=True)
    DATA.write_text(json.dumps(games, indent=1) + "\n")
    print(f"{len(games)} reference games -> {DATA}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
