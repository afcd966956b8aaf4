"""A played game drawn headless: a video, one frame as a PNG, and its time series.

Used by ``python -m pegame.replay DIR --video out.mp4 | --png out.png | --series
out.png``, on a machine with no display or GPU. The game comes from its Rerun recording
(:func:`pegame.recorders.rerun.readback.read_game`: poses, detections, the recorded
visibility outline, the belief's particles, distance, estimation error, N_eff) or, for a
game recorded with ``recorder=none``, from its job's ``trajectory.csv`` and
``.hydra/config.yaml`` (poses and detections; the visibility outline is computed again
from the poses with the recorder's own kernel and ray count, the belief is not in the file, so no
particles, estimation error or N_eff).

Frames are drawn by :mod:`pegame.render`; the video is H.264 in MP4, written by the ffmpeg
that the imageio-ffmpeg wheel ships (nothing to install on the machine), at the game's
own pace (one frame per control tick shown at ``control_hz`` frames per second, times
``speed``).
"""

from __future__ import annotations

import csv
import io
import itertools
import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from pegame.errors import PegameError
from pegame.recorders.rerun.readback import RecordedGame, read_game
from pegame.render import FrameRenderer, FrameState

#: most frames per second of video: a faster game is shown every n-th tick
MAX_FPS = 25.0


class MovieError(PegameError):
    """The game cannot be drawn: no recording or trajectory, or an unreadable one."""


def load_game(path: str | Path) -> RecordedGame:
    """The game of a recording (``*.rrd``, ``*.failed.rrd``) or of a job directory's
    ``trajectory.csv`` (module docstring)."""
    path = Path(path)
    if path.is_file():
        try:
            return read_game(path)
        except (ValueError, OSError) as exc:
            raise MovieError(f"cannot read the recording {path}: {exc}") from exc
    return trajectory_game(path)


def trajectory_game(job_dir: Path) -> RecordedGame:
    """A 1v1 or team game from ``job_dir/trajectory.csv`` and its ``.hydra/config.yaml``."""
    from omegaconf import OmegaConf

    from pegame.config import plain, resolve_map_path
    from pegame.grid import load_map
    from pegame.recorders.rerun import RerunRecorder
    from pegame.types import Camera
    from pegame.visibility.outlines import drawn_outlines

    table, config_file = job_dir / "trajectory.csv", job_dir / ".hydra" / "config.yaml"
    if not table.is_file() or not config_file.is_file():
        raise MovieError(
            f"{job_dir} holds no recording (*.rrd) and no trajectory.csv with .hydra/config.yaml; "
            "play with recorder=rerun, or with game.trials=1 for a trajectory."
        )
    cfg = OmegaConf.load(config_file)
    grid = load_map(resolve_map_path(str(cfg.env.map)))
    with table.open(newline="") as handle:
        reader = csv.reader(handle)
        header = next(reader)
        rows = np.array([[float(v) for v in row] for row in reader], dtype=float)
    column = {name: rows[:, i] for i, name in enumerate(header)}
    members = {
        role: sorted(
            {
                name.rsplit("_", 1)[0]
                for name in header
                if name.startswith(role) and name.endswith("_x")
            }
        )
        for role in ("pursuer", "evader")
    }
    poses = {
        role: np.stack(
            [np.column_stack([column[f"{m}_{a}"] for a in ("x", "y", "theta")]) for m in names]
        )
        for role, names in members.items()
    }
    detected = column["detected"] if "detected" in column else column["detected_0"]
    pursuer, evader = poses["pursuer"][0], poses["evader"][0]
    camera = Camera(**plain(cfg.camera))
    rays = int(cfg.recorder.get("outline_rays", RerunRecorder.Config.outline_rays))
    points, lengths = drawn_outlines(
        grid, pursuer[:, 0], pursuer[:, 1], pursuer[:, 2], camera, rays
    )
    outlines = np.split(points[:, :2].astype(float), np.cumsum(lengths)[:-1])
    nothing = np.full(len(rows), np.nan)
    return RecordedGame(
        grid=grid,
        config={
            "camera.fov": camera.fov,
            "camera.near": camera.near,
            "camera.far": camera.far,
            "pursuer.radius": float(cfg.pursuer.radius),
            "evader.radius": float(cfg.evader.radius),
        },
        steps=column["step"].astype(np.int64),
        time=column["time"],
        pursuers=poses["pursuer"],
        evaders=poses["evader"],
        detected=detected,
        distance=np.hypot(*(pursuer[:, :2] - evader[:, :2]).T),
        estimate_error=nothing,
        n_eff=nothing.copy(),
        means=np.full((len(rows), 2), np.nan),
        outlines=[[outline] for outline in outlines],
        particles=[np.empty((0, 2))] * len(rows),
    )


def renderer(game: RecordedGame, size: int = 480) -> FrameRenderer:
    """A renderer for ``game``'s map, camera and bodies."""
    return FrameRenderer(
        game.grid,
        fov=game.setting("camera.fov", np.pi / 3),
        near=game.setting("camera.near", 0.3),
        far=game.setting("camera.far", 5.0),
        pursuer_radius=game.setting("pursuer.radius", 0.2),
        evader_radius=game.setting("evader.radius", 0.25),
        size=size,
    )


def state(game: RecordedGame, i: int) -> FrameState:
    """What is drawn at recorded tick ``i``: pursuer 0's outline and detection flag (the
    recording keeps pursuer 0's region only; the others get their FOV wedge)."""
    n = game.pursuers.shape[0]
    return FrameState(
        game.pursuers[:, i],
        game.evaders[:, i],
        [bool(game.detected[i] > 0.5)] + [False] * (n - 1),
        [game.outlines[i], *([None] * (n - 1))],
        game.particles[i],
        game.means[i],
        float(game.time[i]),
    )


def frames(game: RecordedGame, size: int = 480, every: int = 1) -> Iterator[np.ndarray]:
    """Every ``every``-th tick's frame, in order."""
    draw = renderer(game, size)
    for i in range(0, len(game.steps), every):
        yield draw.frame(state(game, i))


def tick_at(game: RecordedGame, seconds: float | None) -> int:
    """The recorded tick nearest ``seconds`` of simulated time (None: the last)."""
    if seconds is None:
        return len(game.steps) - 1
    return int(np.argmin(np.abs(game.time - seconds)))


def write_video(game: RecordedGame, path: str | Path, size: int = 480, speed: float = 1.0) -> Path:
    """The game as an MP4 at ``speed`` times its pace (module docstring); returns ``path``."""
    import imageio_ffmpeg

    if speed <= 0:
        raise MovieError(f"speed must be positive, not {speed}")
    dt = float(np.median(np.diff(game.time))) if len(game.time) > 1 else 0.1
    every = max(1, math.ceil(speed / (dt * MAX_FPS) - 1e-9))  # ticks per frame
    fps = speed / (every * dt)
    path = Path(path)
    images = frames(game, size, every)
    first = next(images)  # its size is the video's
    height, width = first.shape[:2]
    writer = imageio_ffmpeg.write_frames(
        str(path),
        (width + width % 2, height + height % 2),  # H.264 wants even sizes
        fps=fps,
        codec="libx264",
        pix_fmt_out="yuv420p",
        macro_block_size=1,
        ffmpeg_log_level="error",
    )
    writer.send(None)
    for image in itertools.chain([first], images):
        padded = np.pad(image, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")
        writer.send(np.ascontiguousarray(padded))
    writer.close()
    return path


def write_png(
    game: RecordedGame, path: str | Path, seconds: float | None = None, size: int = 480
) -> Path:
    """The frame at ``seconds`` (None: the last) as a PNG; returns ``path``."""
    from PIL import Image

    from pegame.files import write_atomic

    image = renderer(game, size).frame(state(game, tick_at(game, seconds)))
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG")
    write_atomic(Path(path), buffer.getvalue())
    return Path(path)


def write_series(game: RecordedGame, path: str | Path, title: str = "") -> Path:
    """The game's detection, true distance, estimation error and N_eff against time as a
    PNG (:func:`pegame.figures.plot_time_series`); returns ``path``."""
    from pegame.figures import plot_time_series

    return plot_time_series(
        game.time,
        [
            ("detected", "#e08000", game.detected),
            ("distance (m)", "#dc2828", game.distance),
            ("estimation error (m)", "#1e5adc", game.estimate_error),
            ("N_eff", "#6e00aa", game.n_eff),
        ],
        path,
        title=title,
    )
