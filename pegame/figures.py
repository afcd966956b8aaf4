"""Static figures of one game, drawn with matplotlib's Agg backend (no display needed)."""

from __future__ import annotations

import io
import textwrap
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from pegame.files import write_atomic
from pegame.game import TRAJECTORY_HEADER
from pegame.grid import OccupancyGrid

PURSUER_COLOR = "#dc2828"
EVADER_COLOR = "#1ea03c"
#: most map cells drawn per side: a larger map is drawn by blocks of cells, each as dark
#: as its darkest cell (the figure is about 840 px wide; matplotlib would otherwise
#: convert every cell of a 4000 x 4000 map to RGBA floats, seconds and gigabytes)
MAX_DRAWN_CELLS = 1000


def map_shades(grid: OccupancyGrid) -> np.ndarray:
    """Grey level per cell in [0, 1] (row 0 = lowest y): free white, occupied dark grey,
    unknown mid grey, and ``scale``-mode values in between."""
    occupancy = np.clip(grid.data.astype(float), 0.0, 100.0) / 100.0
    return np.where(grid.data < 0, 0.6, 1.0 - 0.75 * occupancy)


def drawn_shades(grid: OccupancyGrid) -> tuple[np.ndarray, int]:
    """The map's shades as drawn and the edge (cells) of the square block each stands for:
    :func:`map_shades` itself (block 1) up to MAX_DRAWN_CELLS cells a side, else the
    darkest shade of each block, the last blocks padded with the edge cells' shades."""
    block = -(-max(grid.height, grid.width) // MAX_DRAWN_CELLS)
    if block == 1:
        return map_shades(grid), 1
    # The blocks' minimum is taken over one byte per cell, the rank of the cell's value
    # among the shades of all 256 values (a float shade per cell costs 8 bytes a pass).
    values = np.arange(-128, 128, dtype=np.int8)
    shade_of_value = map_shades(OccupancyGrid(values.reshape(1, -1), grid.resolution))[0]
    order = np.argsort(shade_of_value, kind="stable")
    rank = np.empty(256, dtype=np.uint8)
    rank[order] = np.arange(256)
    ranks = rank[grid.data.view(np.uint8) ^ 0x80]  # int8 value v -> index v + 128
    rows, cols = -(-grid.height // block), -(-grid.width // block)
    padding = ((0, rows * block - grid.height), (0, cols * block - grid.width))
    darkest = np.pad(ranks, padding, "edge").reshape(rows, block, cols, block).min(axis=(1, 3))
    return shade_of_value[order][darkest], block


def plot_trajectory(
    grid: OccupancyGrid,
    trajectory: Sequence[Sequence],
    path: str | Path,
    *,
    pairing: str | None = None,
    tracking_rate: float | None = None,
    title: str | None = None,
    header: Sequence[str] | None = None,
) -> Path:
    """Draw the map and every agent's trajectory and write them as a PNG to ``path``.

    trajectory: rows with the columns of ``header`` (numbers or their text, as in
    trajectory.csv): by default ``pegame.game.TRAJECTORY_HEADER`` (one pursuer, one
    evader), or a team game's :func:`pegame.game.team_header` (``pursuer_<i>_x``, ...),
    whose members are drawn in shades of their role's colour. The axes are map-frame metres, the map drawn with
    its resolution and origin (yaw included); the pursuer is red, the evader green, each
    start a dot. The title is ``title`` when given (wrapped to the figure's width), else
    the map's name with the pairing (e.g. 'S-R') and the tracking rate in [0, 1] when
    given. The file is written atomically. Returns ``path``.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.transforms import Affine2D

    header = tuple(header or TRAJECTORY_HEADER)
    rows = np.asarray(trajectory, dtype=float).reshape(-1, len(header))
    column = {name: rows[:, i] for i, name in enumerate(header)}
    figure = Figure(figsize=(7.0, 7.0 * grid.height / max(grid.width, 1) + 0.6), dpi=120)
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    ox, oy, yaw = grid.origin
    shades, block = drawn_shades(grid)
    width, height = (
        shades.shape[1] * block * grid.resolution,
        shades.shape[0] * block * grid.resolution,
    )
    image = axes.imshow(
        shades,
        cmap="gray",
        vmin=0.0,
        vmax=1.0,
        origin="lower",
        extent=(ox, ox + width, oy, oy + height),
        interpolation="nearest",
    )
    if yaw:
        # The grid is rotated by yaw about its origin corner.
        image.set_transform(Affine2D().rotate_around(ox, oy, yaw) + axes.transData)
        corners = (
            Affine2D()
            .rotate_around(ox, oy, yaw)
            .transform([(ox, oy), (ox + width, oy), (ox, oy + height), (ox + width, oy + height)])
        )
        axes.set_xlim(corners[:, 0].min(), corners[:, 0].max())
        axes.set_ylim(corners[:, 1].min(), corners[:, 1].max())
    for name, key, color in agents(header):
        x, y = column[f"{key}_x"], column[f"{key}_y"]
        axes.plot(x, y, color=color, linewidth=1.5, label=name)
        if len(x):
            axes.plot(x[:1], y[:1], "o", color=color, markersize=7, markeredgecolor="black")
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.legend(loc="best", framealpha=0.9)
    axes.set_title(
        textwrap.fill(title, 70) if title else _title(grid.name, pairing, tracking_rate),
        fontsize=10,
    )
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    write_atomic(path, buffer.getvalue())
    return Path(path)


def agents(header: Sequence[str]) -> list[tuple[str, str, str]]:
    """(label, column prefix, colour) of each agent of a trajectory ``header``: 'pursuer'
    and 'evader' in 1v1, 'pursuer 0', 'pursuer 1', ... in a team game, member 0 in its
    role's colour and the others lighter."""
    from matplotlib.colors import to_hex, to_rgb

    found = []
    for role, base in (("pursuer", PURSUER_COLOR), ("evader", EVADER_COLOR)):
        if f"{role}_x" in header:
            found.append((role, role, base))
            continue
        members = 0
        while f"{role}_{members}_x" in header:
            members += 1
        for k in range(members):
            fade = 0.6 * k / max(members, 1)  # towards white, never all the way
            red, green, blue = (c + (1 - c) * fade for c in to_rgb(base))
            color = to_hex((red, green, blue))
            found.append((f"{role} {k}", f"{role}_{k}", color))
    return found


def _title(map_name: str, pairing: str | None, tracking_rate: float | None) -> str:
    """'S-R on hall: tracking rate 81.0%', leaving out what is not given."""
    title = f"{pairing} on {map_name}" if pairing else map_name
    if tracking_rate is not None:
        title += f": tracking rate {100 * tracking_rate:.1f}%"
    return title


def plot_time_series(
    time: np.ndarray,
    series: Sequence[tuple[str, str, np.ndarray]],
    path: str | Path,
    *,
    title: str = "",
) -> Path:
    """One panel per series against simulated time (s), sharing the time axis, written as a
    PNG to ``path`` atomically. series: (label with its unit, colour, (T,) values; NaN
    where a tick has none: the panel says "not recorded" when all are NaN). Returns
    ``path``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8.0, 1.6 * len(series) + 0.8), dpi=110)
    FigureCanvasAgg(figure)
    panels = figure.subplots(len(series), 1, sharex=True, squeeze=False)[:, 0]
    for axes, (label, color, values) in zip(panels, series):
        values = np.asarray(values, dtype=float)
        if np.isfinite(values).any():
            axes.plot(time, values, color=color, linewidth=1.2, drawstyle="steps-post")
        else:
            axes.text(0.5, 0.5, "not recorded", ha="center", va="center", transform=axes.transAxes)
        axes.set_ylabel(label, fontsize=9)
        axes.grid(alpha=0.3)
    panels[-1].set_xlabel("time (s)")
    if title:
        panels[0].set_title(textwrap.fill(title, 90), fontsize=10)
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    write_atomic(path, buffer.getvalue())
    return Path(path)
