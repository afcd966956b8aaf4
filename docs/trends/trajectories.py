"""Trajectories of the smart pursuer against the random evader under two tracking readings
(docs/trends/README.md): the hall, seed 0, v_p/v_e 0.5 and 2, the first 30 s, one PNG
each (``trajectory_<reading>_<ratio>.png``) with the tracking rate and the losses by
cause in the title.

    python docs/trends/trajectories.py --out docs/trends
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np

from pegame.config import compose
from pegame.figures import plot_trajectory
from pegame.game import Game, trajectory_row

SMART_R = ["pursuer=smart", "pursuer.detour=false", "evader=random", "evader.model=action"]
READINGS = {"paper_conditions": "paper_conditions", "goal_tracking": "reading_goal_tracking"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/trends"))
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    for name, preset in READINGS.items():
        for ratio in (0.5, 2.0):
            overrides = [f"+experiment={preset}", "env=hall", f"game.speed_ratio={ratio}"]
            game = Game(compose([*overrides, *SMART_R]), seed=args.seed)
            loop = game.start()
            ticks = [loop.advance() for _ in range(round(args.seconds / game.context.control_dt))]
            causes = Counter(loss.cause for t in ticks for loss in t.losses)
            tracked = np.mean([t.detection is not None for t in ticks])
            lost = ", ".join(f"{n} {c}" for c, n in causes.most_common()) or "none"
            plot_trajectory(
                game.context.grid,
                [trajectory_row(t) for t in ticks],
                args.out / f"trajectory_{name}_{ratio:g}.png",
                title=f"{name}, S-R, hall, v_p/v_e {ratio:g}, seed {args.seed}, first "
                f"{args.seconds:g} s: tracked {tracked:.0%}; losses: {lost}",
            )


if __name__ == "__main__":
    main()
