"""The per-call figures of README's "What was found and fixed", each beside what it replaced.

    python docs/performance/micro.py

Best of 5 repeats, in us per call, on the enclosed map: the smart evader's cell centres of
500 cells (one numba pass against the numpy passes of ``cell_to_world``), the single env's
32 x 32 crop (the lattice route against the division), ``Planner.shared`` (its cached
parameters against binding the constructor's signature), the particle filter's
deterministic exp of 2000 arguments against numpy's, and building a ``Pose`` and reading
its fields 30 times: the slotted value type against an ``__init__`` that fills the
instance ``__dict__`` (this release's earlier form) and the plain frozen dataclass (the
previous release's).
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import timeit

import numpy as np

from pegame.config import compose
from pegame.game import Game
from pegame.grid.cells import cell_centres
from pegame.navigation.planner import Planner
from pegame.numerics import exps
from pegame.observe.crop import LocalCrop, _crop
from pegame.types import Pose


@dataclasses.dataclass(frozen=True)
class PlainPose:
    """The previous release's value type: a plain frozen dataclass."""

    x: float
    y: float
    theta: float = 0.0


class DictPose(PlainPose):
    """This release's earlier value type: the fields written into the instance dict."""

    def __init__(self, x: float, y: float, theta: float = 0.0) -> None:
        fields = self.__dict__
        fields["x"], fields["y"], fields["theta"] = x, y, theta


def thirty_reads(pose) -> float:
    """Read the fields of ``pose`` 30 times."""
    total = 0.0
    for _ in range(10):
        total += pose.x + pose.y + pose.theta
    return total


def per_call_us(function, number: int = 2000) -> float:
    """Best of 5 repeats of ``number`` calls, us per call."""
    return min(timeit.repeat(function, number=number, repeat=5)) / number * 1e6


def main() -> None:
    grid = Game(compose(["recorder=none", "env=enclosed"])).context.grid
    rng = np.random.default_rng(0)
    cells = np.sort(rng.choice(grid.data.size, 500, replace=False))

    def centres_by_numpy():
        return np.stack(grid.cell_to_world(*np.divmod(cells, grid.width)), axis=-1)

    crop = LocalCrop(grid, 32, 0.2)
    out = np.empty(crop.size, dtype=np.float32)
    c, s = math.cos(0.3), math.sin(0.3)

    def crop_by_division():
        _crop(crop._pooled, crop._off_x, crop._off_y, 5.0, 6.0, c, s, *crop._origin, out)

    def bound_signature():
        arguments = inspect.signature(Planner).bind(grid, 0.2)
        arguments.apply_defaults()

    exponents = -rng.random(2000) * 30.0
    rows = [
        (
            "cell centres, 500 cells",
            lambda: cell_centres(cells, grid.width, grid.kernel_frame),
            centres_by_numpy,
        ),
        ("crop 32 x 32", lambda: crop(5.0, 6.0, 0.3, out), crop_by_division),
        ("Planner.shared", lambda: Planner.shared(grid, 0.2), bound_signature),
        (
            "exp of 2000 (pegame.numerics.exps / numpy)",
            lambda: exps(exponents),
            lambda: np.exp(exponents),
        ),
    ]
    for other in (DictPose, PlainPose):
        pose, reference = Pose(1.0, 2.0, 0.5), other(1.0, 2.0, 0.5)
        rows.append(
            (
                f"Pose built / {other.__name__}",
                lambda: Pose(1.0, 2.0, 0.5),
                lambda other=other: other(1.0, 2.0, 0.5),
            )
        )
        rows.append(
            (
                f"30 Pose reads / {other.__name__}",
                lambda pose=pose: thirty_reads(pose),
                lambda reference=reference: thirty_reads(reference),
            )
        )
    for name, new, old in rows:
        new(), old()  # compile and warm
        print(
            f"{name:40s} {per_call_us(new):8.2f} us   (before / other: {per_call_us(old):8.2f} us)"
        )


if __name__ == "__main__":
    main()
