"""Headless replays (pegame.movie and ``python -m pegame.replay --video/--png/--series``):
the video's frames are the game's, a frame is the renderer's, a game without a recording
is drawn from its trajectory, and bad choices are one-line errors."""

from __future__ import annotations

import csv
import subprocess
import sys

import numpy as np
import pytest
from omegaconf import OmegaConf
from PIL import Image

from pegame.config import compose
from pegame.game import Game
from pegame.movie import load_game, renderer, state, tick_at, write_png, write_series, write_video
from pegame.replay import main

SHORT = ["recorder=rerun", "game.t_max=3", "env=enclosed"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A job dir as the app leaves it: game.rrd, trajectory.csv and .hydra/config.yaml."""
    out_dir = tmp_path_factory.mktemp("run")
    cfg = compose(SHORT)
    outcome = Game(cfg).play(out_dir)
    with (out_dir / "trajectory.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(outcome.header)
        writer.writerows(outcome.trajectory)
    (out_dir / ".hydra").mkdir()
    OmegaConf.save(cfg, out_dir / ".hydra" / "config.yaml")
    return out_dir


def test_the_video_has_one_frame_per_tick_at_the_games_pace_and_shows_it(run_dir, tmp_path):
    import imageio_ffmpeg

    game = load_game(run_dir / "game.rrd")
    path = write_video(game, tmp_path / "game.mp4")
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    frames = [
        np.frombuffer(f, dtype=np.uint8).reshape(meta["size"][1], meta["size"][0], 3)
        for f in reader
    ]
    assert meta["fps"] == pytest.approx(10.0)  # control_hz: the game's own pace
    assert len(frames) == len(game.steps)
    expected = renderer(game).frame(state(game, 10))
    decoded = frames[10][: expected.shape[0], : expected.shape[1]].astype(int)
    assert np.abs(decoded - expected).mean() < 6.0  # H.264 is lossy, the picture the same
    faster = write_video(game, tmp_path / "fast.mp4", speed=5.0)
    meta = next(imageio_ffmpeg.read_frames(str(faster)))
    assert meta["duration"] == pytest.approx(len(game.steps) * 0.1 / 5.0, abs=0.25)


def test_a_png_is_the_renderers_frame_at_the_time_asked(run_dir, tmp_path):
    game = load_game(run_dir / "game.rrd")
    i = tick_at(game, 1.5)
    assert game.time[i] == pytest.approx(1.5)
    path = write_png(game, tmp_path / "frame.png", 1.5)
    assert np.array_equal(np.asarray(Image.open(path)), renderer(game).frame(state(game, i)))


def test_without_a_recording_the_game_is_drawn_from_its_trajectory(run_dir, tmp_path):
    recorded = load_game(run_dir / "game.rrd")
    (tmp_path / "job").mkdir()
    for name in ("trajectory.csv", ".hydra"):
        (tmp_path / "job" / name).symlink_to(run_dir / name)
    rebuilt = load_game(tmp_path / "job")
    assert np.allclose(rebuilt.pursuers, recorded.pursuers, atol=1e-5)
    assert np.array_equal(rebuilt.detected, recorded.detected)
    assert np.isnan(rebuilt.n_eff).all()  # the trajectory holds no belief
    outline, again = rebuilt.outlines[5][0], recorded.outlines[5][0]
    assert np.allclose(outline, again, atol=1e-4)  # the recorder's own kernel, the same region


def test_the_series_figure_has_a_panel_per_measure(run_dir, tmp_path):
    path = write_series(load_game(run_dir / "game.rrd"), tmp_path / "series.png")
    image = np.asarray(Image.open(path).convert("RGB"))
    purple = (np.abs(image.astype(int) - (110, 0, 170)).sum(axis=2) < 40).sum()
    assert image.shape[0] > image.shape[1] * 0.8 and purple > 50  # four panels; N_eff drawn


def test_the_cli_draws_one_game_and_refuses_to_guess_between_several(run_dir, tmp_path, capsys):
    assert (
        main([str(run_dir), "--png", str(tmp_path / "a.png"), "--series", str(tmp_path / "s.png")])
        == 0
    )
    assert (tmp_path / "a.png").is_file() and (tmp_path / "s.png").is_file()
    (tmp_path / "sweep" / "0").mkdir(parents=True)
    (tmp_path / "sweep" / "1").mkdir()
    for k in ("0", "1"):
        (tmp_path / "sweep" / k / "game.rrd").symlink_to(run_dir / "game.rrd")
    assert main([str(tmp_path / "sweep"), "--png", str(tmp_path / "b.png")]) == 2
    err = capsys.readouterr().err
    assert "2 games are recorded here; name one with --game" in err and "0/game.rrd" in err
    assert main([str(tmp_path / "sweep"), "--game", "1/", "--png", str(tmp_path / "b.png")]) == 0


@pytest.mark.slow
def test_replay_video_runs_headless_from_the_command_line(run_dir, tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "pegame.replay", str(run_dir), "--video", str(tmp_path / "v.mp4")],
        capture_output=True,
        text=True,
        env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)},  # no DISPLAY, no GPU
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "v.mp4").stat().st_size > 1000
