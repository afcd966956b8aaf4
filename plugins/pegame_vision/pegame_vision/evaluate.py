"""``detector=vision`` or ``detector=person`` measured against ``detector=segmentation``
on played games.

Games are played in PyBullet (``sim=pybullet``, needs pegame-pybullet) with the reference
segmentation detector driving the smart pursuer, so that both detectors see the same
frames whatever the detector under test does; it runs beside the reference on every
frame, and its latency is the wall-clock time of its ``detect`` on each new frame (and its
CPU time, the process's over the same call, which a machine shared with other jobs does
not inflate). Each frame falls in one of three classes:

- positive: the reference sees the evader within ``max_range`` m (horizontal distance
  from the camera) with at least ``min_visible`` of its body visible (occlusion and the
  image border included; :meth:`PybulletSimulator.evader_visible_fraction`);
- negative: the reference does not see the evader at all;
- ignored: the evader is visible but farther or less visible than that (as KITTI ignores
  truncated and occluded objects: a detection there is neither right nor wrong).

A vision detection is correct when its box overlaps the reference's with IoU >=
``iou_threshold``. Recall is the fraction of positives detected correctly; precision the
fraction of vision detections on positive and negative frames that are correct; the mean
IoU is over the positives the vision detector reports; the position error is the median
distance (m) from a correct detection's map position to the evader's true position.
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Iterable, Mapping
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from pegame import registry
from pegame.api import Detector
from pegame.config import compose
from pegame.game import Game
from pegame.types import BoundingBox, Detection, Pose, SensorFrame

if TYPE_CHECKING:  # pragma: no cover - typing only (evaluate imports it: sim=pybullet)
    from pegame_pybullet.sim import PybulletSimulator

#: one judged frame: its kind (positive, negative, ignored), the reference's and the
#: vision detector's detections, the evader's true pose
Row = tuple[str, Detection | None, Detection | None, Pose]


def iou(a: BoundingBox, b: BoundingBox) -> float:
    """Intersection over union of two boxes (same pixel frame)."""
    width = min(a.x + a.w, b.x + b.w) - max(a.x, b.x)
    height = min(a.y + a.h, b.y + b.h) - max(a.y, b.y)
    inter = max(0.0, width) * max(0.0, height)
    union = a.w * a.h + b.w * b.h - inter
    return inter / union if union > 0 else 0.0


class _Judge(Detector):
    """Stands in for the game's detector: returns the reference's detection and records,
    per frame, the vision detector's beside it."""

    def __init__(
        self,
        reference: Detector,
        vision: Detector,
        sim: PybulletSimulator,
        max_range: float,
        min_visible: float,
        measure_visible: bool = False,
    ) -> None:
        super().__init__(reference.config, reference.context, reference.rng)
        self.reference, self.vision, self.sim = reference, vision, sim
        self.max_range, self.min_visible = max_range, min_visible
        self.measure_visible = measure_visible  # visible fraction of every frame with the evader
        self.rows: list[Row] = []
        #: per row, the frame's time (s), the camera's pose and the evader's visible fraction
        #: (None: not measured)
        self.views: list[tuple[float, Pose, float | None]] = []
        self.latencies: list[float] = []  # s, the detector under test's detect per new frame
        self.cpu: list[float] = []  # s of this process's CPU time in the same calls
        self._frame: SensorFrame | None = None

    def reset(self) -> None:
        self.reference.reset()
        self.vision.reset()

    def detect(self, frame: SensorFrame) -> Detection | None:
        evader = frame.evader_truth
        if evader is None:
            raise RuntimeError("The evaluation needs frames that carry the evader's true pose.")
        truth = self.reference.detect(frame)
        start, cpu = time.perf_counter(), time.process_time()
        seen = self.vision.detect(frame)
        if frame is not self._frame:  # a reused frame costs nothing
            self.latencies.append(time.perf_counter() - start)
            self.cpu.append(time.process_time() - cpu)
            self._frame = frame
        visible = None
        if truth is not None and self.measure_visible:
            visible = self.sim.evader_visible_fraction()
        if truth is None:
            kind = "negative"
        elif (
            frame.camera_pose.distance_to(evader) <= self.max_range
            and (visible if visible is not None else self.sim.evader_visible_fraction())
            >= self.min_visible
        ):
            kind = "positive"
        else:
            kind = "ignored"
        self.rows.append((kind, truth, seen, evader))
        self.views.append((frame.time, frame.camera_pose, visible))
        return truth


def evaluate(
    env: str = "enclosed",
    seeds: Iterable[int] = range(3),
    t_max: float = 60.0,
    max_range: float = 4.0,
    min_visible: float = 0.3,
    iou_threshold: float = 0.5,
    vision: Mapping[str, Any] | None = None,
    overrides: Iterable[str] = (),
    detector: str = "vision",
) -> dict[str, Any]:
    """Precision, recall, mean box IoU and latency of ``detector`` (``vision`` or ``person``,
    with the parameters in ``vision``, defaults otherwise) against ``detector=segmentation``
    over S-S games on ``env``, one per seed, ``t_max`` s each, the game config changed by
    ``overrides`` (e.g. ``sim.camera_tilt=0``); see the module docstring. The scores are
    named ``<detector>_precision`` and so on."""
    rows, latencies, cpu = [], [], []
    for seed in seeds:
        judge = judged_game(env, seed, t_max, detector, vision, overrides, max_range, min_visible)
        rows += judge.rows
        latencies += judge.latencies
        cpu += judge.cpu
    return _score(rows, iou_threshold, latencies, cpu, detector)


def judged_game(
    env: str,
    seed: int,
    t_max: float,
    detector: str,
    vision: Mapping[str, Any] | None = None,
    overrides: Iterable[str] = (),
    max_range: float = 4.0,
    min_visible: float = 0.3,
    measure_visible: bool = False,
) -> _Judge:
    """One S-S game on ``env`` driven by ``detector=segmentation`` with ``detector`` (its
    parameters in ``vision``) judged beside it; the judge holds the game's rows."""
    from pegame_pybullet.sim import PybulletSimulator

    tested_cls = registry.load("detector", detector)
    tested_config = registry.make_config("detector", tested_cls, dict(vision or {}))
    game = Game(
        compose(
            [
                "sim=pybullet",
                "detector=segmentation",
                "pursuer=smart",
                "evader=smart",
                "recorder=none",
                f"env={env}",
                f"game.t_max={t_max}",
                f"game.seed={seed}",
                *overrides,
            ]
        )
    )
    tested = tested_cls(tested_config, game.context, np.random.default_rng(seed))
    sim = PybulletSimulator.narrow(game.plugins.sim)  # the games' sim=pybullet
    judge = _Judge(game.plugins.detector, tested, sim, max_range, min_visible, measure_visible)
    game.plugins = replace(game.plugins, detectors=((judge,),))
    with tempfile.TemporaryDirectory() as out:
        game.play(out)
    return judge


def _score(
    rows: list[Row],
    iou_threshold: float,
    latencies: list[float],
    cpu: list[float],
    name: str = "vision",
) -> dict[str, Any]:
    """The scores of recorded (kind, reference, vision, true evader pose) rows and the
    detector's wall and CPU time per frame (s), named ``<name>_precision`` and so on."""
    positives = [  # a positive frame has the reference's detection
        (truth, seen, evader)
        for kind, truth, seen, evader in rows
        if kind == "positive" and truth is not None
    ]
    judged = [row for row in rows if row[0] != "ignored" and row[2] is not None]
    overlaps = [iou(truth.box, seen.box) for truth, seen, _ in positives if seen is not None]
    matched = [
        (seen, evader)
        for truth, seen, evader in positives
        if seen is not None and iou(truth.box, seen.box) >= iou_threshold
    ]
    errors = [math.hypot(seen.position[0] - e.x, seen.position[1] - e.y) for seen, e in matched]
    return {
        f"{name}_precision": len(matched) / len(judged) if judged else None,
        f"{name}_recall": len(matched) / len(positives) if positives else None,
        f"{name}_iou": float(np.mean(overlaps)) if overlaps else None,
        f"{name}_position_error_m": float(np.median(errors)) if errors else None,
        f"{name}_latency_ms": 1e3 * float(np.median(latencies)) if latencies else None,
        f"{name}_latency_p95_ms": 1e3 * float(np.quantile(latencies, 0.95)) if latencies else None,
        f"{name}_cpu_ms": 1e3 * float(np.median(cpu)) if cpu else None,
        "frames": len(rows),
        "positives": len(positives),
        "negatives": sum(1 for row in rows if row[0] == "negative"),
        "ignored": sum(1 for row in rows if row[0] == "ignored"),
    }
