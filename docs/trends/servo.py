"""The smart pursuer's servo, loss causes and the random agents' motion, measured tick by
tick (docs/trends/README.md, issue 29).

Plays games in-process (``pegame.game.Game`` on a composed config, the same games
``python -m pegame`` plays for these overrides and seeds) and writes, per reading and
speed ratio: the tracking rate, the servo's commanded and achieved speed and turn rate
while the evader is detected, how often the command is saturated, the range kept, the
heading change over one detection period per radian of the evader's bearing at that
detection (the servo's loop gain on a held detection), the losses by cause and the
seconds lost per loss; and the random agents' displacement per second and per ten
seconds.

    python docs/trends/servo.py --seeds 10 --out docs/trends
"""

from __future__ import annotations

import argparse
import math
import sys
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

from pegame.config import compose
from pegame.game import Game
from pegame.types import wrap_angle

RATIOS = (0.5, 1.0, 2.0)
SMART_R = ["pursuer=smart", "pursuer.detour=false", "evader=random", "evader.model=action"]
RANDOM = {
    "action": ["pursuer=random", "pursuer.model=action", "evader=random", "evader.model=action"],
    "waypoint": ["pursuer=random", "evader=random"],
}


def play(overrides: list[str], seed: int) -> list:
    """The ticks of one game (a list of :class:`pegame.api.Tick`)."""
    loop = Game(compose(overrides), seed=seed).start()
    return [loop.advance() for _ in range(loop.ticks)]


def servo_row(ticks: list, dt: float, v_max: float, w_max: float, fov: float) -> dict:
    """Per-game sums of the servo's measures (see the module docstring)."""
    s: dict = defaultdict(float)
    losses: Counter = Counter()
    held_gain: list[tuple[float, float]] = []
    last_detection = None
    seen = False  # the time before the first detection is no loss
    for k, t in enumerate(ticks[:-1]):
        nxt = ticks[k + 1]
        for loss in t.losses:
            losses[loss.cause] += 1
        seen = seen or t.detection is not None
        if t.detection is None:
            if seen:
                s["lost"] += dt
                step = math.hypot(nxt.pursuer.x - t.pursuer.x, nxt.pursuer.y - t.pursuer.y)
                s["scan"] += dt * (step < 0.05 * v_max * dt)
                mean = t.belief.mean
                if mean is not None:
                    s["estimated"] += dt
                    s["error"] += dt * math.hypot(mean[0] - t.evader.x, mean[1] - t.evader.y)
                    s["there"] += dt * (
                        math.hypot(mean[0] - t.pursuer.x, mean[1] - t.pursuer.y) < 0.5
                    )
            continue
        v, w = t.commands[0].v, t.commands[0].w
        moved = math.hypot(nxt.pursuer.x - t.pursuer.x, nxt.pursuer.y - t.pursuer.y) / dt
        turned = wrap_angle(nxt.pursuer.theta - t.pursuer.theta) / dt
        s["ticks"] += 1
        s["v_cmd"] += min(abs(v), v_max)
        s["v_got"] += moved
        s["w_cmd"] += min(abs(w), w_max)
        s["w_got"] += abs(turned)
        s["v_sat"] += abs(v) >= v_max - 1e-9
        s["w_sat"] += abs(w) >= w_max - 1e-9
        s["still"] += moved < 0.05 * v_max
        s["range"] += math.hypot(t.evader.x - t.pursuer.x, t.evader.y - t.pursuer.y)
        if t.detection is not last_detection:  # a fresh detection: the servo's new input
            bearing = wrap_angle(
                math.atan2(t.evader.y - t.pursuer.y, t.evader.x - t.pursuer.x) - t.pursuer.theta
            )
            period = ticks[k : k + round(1.0 / dt) + 1]
            if len(period) > 1 and abs(bearing) > 0.05:
                change = sum(
                    wrap_angle(b.pursuer.theta - a.pursuer.theta)
                    for a, b in zip(period, period[1:])
                )
                held_gain.append((bearing, change))
        last_detection = t.detection
    s["detected"] = sum(t.detection is not None for t in ticks) / len(ticks)
    return {"sums": s, "losses": losses, "gain": held_gain}


def servo_table(readings: dict[str, str], env: str, seeds: int) -> list[str]:
    lines = [
        f"### Smart pursuer vs random evader (action), {env}, seeds 0-{seeds - 1}",
        "",
        "While the evader is detected (per control tick): v, w commanded (saturated to the "
        "body) and achieved (from the true poses), share of ticks at the limit, share standing "
        "still (< 5% of v_max), mean range; gain: median heading change over the detection "
        "period following a fresh detection per radian of the evader's true bearing then "
        "(1 = turns onto it, > 2 = overshoots it by more than it was off). Losses per game "
        "by cause, seconds without a detection per loss (after the first detection), the "
        "share of that time the pursuer stood (turning in place: scanning), the estimate's "
        "mean error (m, the estimator's mean against the true evader) and the share of the "
        "lost time the pursuer was within 0.5 m of the estimate, and tracking "
        "(share of ticks detected).",
        "",
        "| reading | v_p/v_e | tracked | v cmd / got (m/s) | v_max | at v_max | w cmd / got (rad/s) "
        "| at w_max | still | range (m) | gain | bearing | turning | blocked | occluded | missed "
        "| far/near | s/loss | scanning | estimate error (m) | at the estimate |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, preset in readings.items():
        for ratio in RATIOS:
            overrides = [
                f"+experiment={preset}",
                f"env={env}",
                f"game.speed_ratio={ratio}",
                *SMART_R,
            ]
            rows = []
            for seed in range(seeds):
                g = Game(compose(overrides), seed=seed)
                ctx = g.context
                loop = g.start()
                ticks = [loop.advance() for _ in range(loop.ticks)]
                rows.append(
                    servo_row(
                        ticks, ctx.control_dt, ctx.pursuer.v_max, ctx.pursuer.w_max, ctx.camera.fov
                    )
                )
                v_max = ctx.pursuer.v_max
            tot: dict = defaultdict(float)
            losses: Counter = Counter()
            gains = []
            for r in rows:
                for key, value in r["sums"].items():
                    if key != "detected":
                        tot[key] += value
                losses.update(r["losses"])
                gains += [c / b for b, c in r["gain"]]
            n = max(tot["ticks"], 1)
            tracked = np.mean([r["sums"]["detected"] for r in rows])
            per = {
                c: losses[c] / seeds
                for c in ("bearing", "turning", "blocked", "occluded", "missed", "far", "near")
            }
            lines.append(
                f"| {name} | {ratio:g} | {tracked:.1%} | {tot['v_cmd'] / n:.2f} / {tot['v_got'] / n:.2f} "
                f"| {v_max:.2f} | {tot['v_sat'] / n:.0%} | {tot['w_cmd'] / n:.2f} / {tot['w_got'] / n:.2f} "
                f"| {tot['w_sat'] / n:.0%} | {tot['still'] / n:.0%} | {tot['range'] / n:.2f} "
                f"| {np.median(gains) if gains else float('nan'):.2f} | {per['bearing']:.1f} "
                f"| {per['turning']:.1f} | {per['blocked']:.1f} | {per['occluded']:.1f} "
                f"| {per['missed']:.1f} | {per['far'] + per['near']:.1f} "
                f"| {tot['lost'] / max(sum(losses.values()), 1):.1f} "
                f"| {tot['scan'] / max(tot['lost'], 1e-9):.0%} "
                f"| {tot['error'] / max(tot['estimated'], 1e-9):.2f} "
                f"| {tot['there'] / max(tot['estimated'], 1e-9):.0%} |"
            )
            print(lines[-1], file=sys.stderr)
    return lines


def displacement_table(env: str, seeds: int) -> list[str]:
    """The random agents' displacement over 1 s and 10 s (m), per model and role."""
    lines = [
        f"### Random agents' displacement, {env}, R-R at v_p/v_e 1, seeds 0-{seeds - 1}",
        "",
        "Straight-line displacement of the true pose over 1 s and over 10 s (mean, m), the "
        "distance travelled per second (m/s) and the share of the map's free area the agent's "
        "centre came within 0.5 m of in the 90 s. Below it, the share of the map's free "
        "cells inside the pursuer's visibility region (FOV wedge, near-far, line of sight; "
        "mean over one tick a second) against R-R's tracking rate in the same games.",
        "",
        "| model | role | 1 s (m) | 10 s (m) | path (m/s) | area covered |",
        "|---|---|---|---|---|---|",
    ]
    views: dict[str, tuple[float, float]] = {}
    for model, extra in RANDOM.items():
        overrides = ["+experiment=paper_conditions", f"env={env}", "game.speed_ratio=1", *extra]
        acc: dict = defaultdict(list)
        for seed in range(seeds):
            g = Game(compose(overrides), seed=seed)
            grid, steps = g.context.grid, round(1.0 / g.context.control_dt)
            loop = g.start()
            ticks = [loop.advance() for _ in range(loop.ticks)]
            for role in ("pursuer", "evader"):
                xy = np.array([[getattr(t, role).x, getattr(t, role).y] for t in ticks])
                for lag, key in ((steps, "1s"), (10 * steps, "10s")):
                    acc[(role, key)].append(np.hypot(*(xy[lag:] - xy[:-lag]).T).mean())
                acc[(role, "path")].append(
                    np.hypot(*np.diff(xy, axis=0).T).sum() / (len(xy) * g.context.control_dt)
                )
                acc[(role, "area")].append(covered(grid, xy))
            free = grid.free.sum()
            acc["view"].append(np.mean([t.region.mask.sum() / free for t in ticks[::10]]))
            acc["tracked"].append(np.mean([t.detection is not None for t in ticks]))
        for role in ("pursuer", "evader"):
            lines.append(
                f"| {model} | {role} | {np.mean(acc[(role, '1s')]):.2f} | {np.mean(acc[(role, '10s')]):.2f} "
                f"| {np.mean(acc[(role, 'path')]):.2f} | {np.mean(acc[(role, 'area')]):.0%} |"
            )
            print(lines[-1], file=sys.stderr)
        views[model] = (np.mean(acc["view"]), np.mean(acc["tracked"]))
    lines += ["", "| model | free area in view | R-R tracked |", "|---|---|---|"]
    lines += [f"| {m} | {v:.1%} | {t:.1%} |" for m, (v, t) in views.items()]
    return lines


def after_loss_table(env: str, seeds: int) -> list[str]:
    """Where a random and a smart evader are 1 s after a loss (paper_conditions)."""
    smart_e = ["evader=smart", "evader.hide_margin=0"]
    lines = [
        f"### After a loss: random against smart evader, {env}, paper_conditions, seeds "
        f"0-{seeds - 1}",
        "",
        "Per loss of track: the evader's true bearing beyond the edge of the field of view "
        "(|bearing| - fov/2, rad; < 0: back inside the wedge) and its range (m) 1 s after the "
        "loss, and its mean speed over the game (m/s).",
        "",
        "| pairing | v_p/v_e | losses/game | beyond the edge at +1 s (rad) | range at +1 s (m) "
        "| evader speed (m/s) |",
        "|---|---|---|---|---|---|",
    ]
    for pairing, evader in (("S-R", SMART_R[2:]), ("S-S", smart_e)):
        for ratio in RATIOS:
            overrides = [
                "+experiment=paper_conditions",
                f"env={env}",
                f"game.speed_ratio={ratio}",
                *SMART_R[:2],
                *evader,
            ]
            beyond, ranges, speeds, count = [], [], [], 0
            for seed in range(seeds):
                g = Game(compose(overrides), seed=seed)
                dt, half = g.context.control_dt, 0.5 * g.context.camera.fov
                loop = g.start()
                ticks = [loop.advance() for _ in range(loop.ticks)]
                later = round(1.0 / dt)
                xy = np.array([[t.evader.x, t.evader.y] for t in ticks])
                speeds.append(np.hypot(*np.diff(xy, axis=0).T).mean() / dt)
                for k, t in enumerate(ticks):
                    if not t.losses or k + later >= len(ticks):
                        continue
                    count += 1
                    a = ticks[k + later]
                    dx, dy = a.evader.x - a.pursuer.x, a.evader.y - a.pursuer.y
                    bearing = wrap_angle(math.atan2(dy, dx) - a.pursuer.theta)
                    beyond.append(abs(bearing) - half)
                    ranges.append(math.hypot(dx, dy))
            lines.append(
                f"| {pairing} | {ratio:g} | {count / seeds:.1f} | {np.median(beyond):+.2f} "
                f"(median) | {np.mean(ranges):.2f} | {np.mean(speeds):.2f} |"
            )
            print(lines[-1], file=sys.stderr)
    return lines


def covered(grid, xy: np.ndarray, radius: float = 0.5) -> float:
    """Share of the grid's free cells within ``radius`` m of a point of ``xy``."""
    rows, cols = np.nonzero(grid.free)
    cells = np.array(grid.cell_to_world(rows, cols)).T
    near = np.zeros(len(cells), dtype=bool)
    for point in xy[::5]:
        near |= np.hypot(*(cells - point).T) <= radius
    return float(near.mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--env", default="hall")
    parser.add_argument("--out", type=Path, default=Path("docs/trends"))
    parser.add_argument("--readings", default="paper_conditions")
    args = parser.parse_args()
    readings = {
        name: name if name == "paper_conditions" else f"reading_{name}"
        for name in args.readings.split(",")
    }
    lines = ["# The servo, loss causes and the random agents, tick by tick", ""]
    lines += servo_table(readings, args.env, args.seeds) + [""]
    lines += after_loss_table(args.env, args.seeds) + [""]
    for env in ("hall", "enclosed", "brick"):
        lines += displacement_table(env, args.seeds) + [""]
    (args.out / "servo.md").write_text("\n".join(lines))


if __name__ == "__main__":
    main()
