"""Tests for pegame.grid: ROS map_server IO, grid frames and the paper maps."""

from __future__ import annotations

import copy
import gc
import math
import pickle
import re
import weakref
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image
from scipy import ndimage

from pegame.errors import MapError
from pegame.grid import OccupancyGrid, load_map, per_grid, save_map
from pegame.grid.cells import cell_centres

MAPS_DIR = Path(str(files("pegame.maps")))

# Image rows top to bottom, and the cells map_server's default trinary mode makes of them:
# p = (255 - v) / 255; p > 0.65 -> 100, p < 0.196 -> 0, else -1 (205 gives p = 0.19608).
PIXELS = np.array([[0, 205, 254], [255, 100, 60]], dtype=np.uint8)
TRINARY = np.array([[0, -1, 100], [100, -1, 0]], dtype=np.int8)  # grid rows bottom to top


def write_yaml(path: Path, image: str = "m.pgm", **keys) -> Path:
    doc = {"image": image, "resolution": 0.05, "origin": [0.0, 0.0, 0.0], **keys}
    path.write_text(yaml.safe_dump(doc))
    return path


def write_p2(path: Path, pixels: np.ndarray, maxval: int = 255) -> None:
    rows = "\n".join(" ".join(str(v) for v in row) for row in pixels)
    h, w = pixels.shape
    path.write_text(f"P2\n# plain PGM\n{w} {h}\n{maxval}\n{rows}\n")


def write_p5(path: Path, pixels: np.ndarray) -> None:
    h, w = pixels.shape
    path.write_bytes(f"P5\n{w} {h}\n255\n".encode() + pixels.astype(np.uint8).tobytes())


def load_pixels(tmp_path: Path, pixels: np.ndarray, **keys) -> OccupancyGrid:
    """Save ``pixels`` (grey (H, W) or (H, W, C)) as PNG with a YAML and load it."""
    Image.fromarray(pixels.astype(np.uint8)).save(tmp_path / "m.png")
    return load_map(write_yaml(tmp_path / "m.yaml", image="m.png", **keys))


# --------------------------------------------------------------------------- loading


def test_plain_p2_pgm_with_defaults(tmp_path):
    write_p2(tmp_path / "m.pgm", PIXELS)
    grid = load_map(write_yaml(tmp_path / "m.yaml"))
    np.testing.assert_array_equal(grid.data, TRINARY)
    assert grid.name == "m" and grid.resolution == 0.05 and grid.origin == (0.0, 0.0, 0.0)


def test_p2_pgm_with_small_maxval_is_rescaled(tmp_path):
    write_p2(tmp_path / "m.pgm", np.array([[0, 15]]), maxval=15)
    grid = load_map(write_yaml(tmp_path / "m.yaml"))
    np.testing.assert_array_equal(grid.data, [[100, 0]])


def test_binary_p5_pgm(tmp_path):
    write_p5(tmp_path / "m.pgm", PIXELS)
    np.testing.assert_array_equal(load_map(write_yaml(tmp_path / "m.yaml")).data, TRINARY)


@pytest.mark.parametrize("suffix", ["png", "bmp"])
def test_grey_png_and_bmp(tmp_path, suffix):
    Image.fromarray(PIXELS).save(tmp_path / f"m.{suffix}")
    grid = load_map(write_yaml(tmp_path / "m.yaml", image=f"m.{suffix}"))
    np.testing.assert_array_equal(grid.data, TRINARY)


@pytest.mark.parametrize("suffix", ["png", "bmp"])
def test_colour_pixels_are_averaged(tmp_path, suffix):
    # means: 0 -> occupied, 85 (p = 0.667) -> occupied, 170 (p = 0.333) -> unknown, 255 -> free
    rgb = np.array([[[0, 0, 0], [255, 0, 0], [255, 255, 0], [255, 255, 255]]], dtype=np.uint8)
    Image.fromarray(rgb).save(tmp_path / f"m.{suffix}")
    grid = load_map(write_yaml(tmp_path / "m.yaml", image=f"m.{suffix}"))
    np.testing.assert_array_equal(grid.data, [[100, 100, -1, 0]])


def test_palette_and_bilevel_images_use_their_colours(tmp_path):
    Image.fromarray(PIXELS).convert("P").save(tmp_path / "p.png")
    Image.fromarray(PIXELS > 128).save(tmp_path / "b.png")
    palette = load_map(write_yaml(tmp_path / "p.yaml", image="p.png"))
    bilevel = load_map(write_yaml(tmp_path / "b.yaml", image="b.png"))
    np.testing.assert_array_equal(palette.data, TRINARY)
    np.testing.assert_array_equal(bilevel.data, [[0, 100, 100], [100, 0, 0]])


def test_alpha_is_not_averaged_in_trinary_mode(tmp_path):
    rgba = np.array([[[205, 205, 205, 255], [0, 0, 0, 0], [255, 255, 255, 255]]])
    np.testing.assert_array_equal(load_pixels(tmp_path, rgba).data, [[-1, 100, 0]])


@pytest.mark.parametrize("negate", [1, True])
def test_negate_swaps_black_and_white(tmp_path, negate):
    # negated p = v / 255: 0 -> free, 255 -> occupied, 100 (0.39) -> unknown
    grid = load_pixels(tmp_path, np.array([[0, 255, 100]]), negate=negate)
    np.testing.assert_array_equal(grid.data, [[0, 100, -1]])


def test_thresholds_are_strict_and_configurable(tmp_path):
    # p = 0.2 (v = 204) and p = 0.8 (v = 51) sit on the thresholds: unknown
    pixels = np.array([[204, 51, 205, 50]])
    grid = load_pixels(tmp_path, pixels, free_thresh=0.2, occupied_thresh=0.8)
    np.testing.assert_array_equal(grid.data, [[-1, -1, 0, 100]])


def test_scale_mode(tmp_path):
    # free 0.2, occupied 0.8: value = int(1 + 98 * (p - 0.2) / 0.6)
    # v 153: p 0.4 -> 33.67 -> 33; v 128: p 0.498 -> 49.68 -> 49; v 102: p 0.6 -> 66.33 -> 66
    pixels = np.array([[255, 153, 128, 102, 0]])
    grid = load_pixels(tmp_path, pixels, mode="scale", free_thresh=0.2, occupied_thresh=0.8)
    np.testing.assert_array_equal(grid.data, [[0, 33, 49, 66, 100]])


def test_scale_mode_transparent_pixels_are_unknown(tmp_path):
    rgba = np.array([[[153, 153, 153, 0], [153, 153, 153, 1], [0, 0, 0, 0], [255, 255, 255, 0]]])
    grid = load_pixels(tmp_path, rgba, mode="scale", free_thresh=0.2, occupied_thresh=0.8)
    np.testing.assert_array_equal(grid.data, [[-1, 33, 100, 0]])


def test_raw_mode(tmp_path):
    pixels = np.array([[0, 37, 100, 101, 255]])
    np.testing.assert_array_equal(
        load_pixels(tmp_path, pixels, mode="raw").data, [[0, 37, 100, -1, -1]]
    )


def test_raw_mode_negated(tmp_path):
    pixels = np.array([[255, 200, 155, 0]])
    grid = load_pixels(tmp_path, pixels, mode="raw", negate=1)
    np.testing.assert_array_equal(grid.data, [[0, 55, 100, -1]])


def test_image_path_relative_to_yaml_or_absolute(tmp_path):
    (tmp_path / "img").mkdir()
    (tmp_path / "conf").mkdir()
    write_p5(tmp_path / "img" / "a.pgm", PIXELS)
    relative = load_map(write_yaml(tmp_path / "conf" / "r.yaml", image="../img/a.pgm"))
    absolute = load_map(write_yaml(tmp_path / "abs.yaml", image=str(tmp_path / "img/a.pgm")))
    np.testing.assert_array_equal(relative.data, TRINARY)
    np.testing.assert_array_equal(absolute.data, TRINARY)
    assert relative.name == "r" and absolute.name == "abs"


def test_origin_and_resolution_are_read(tmp_path):
    write_p5(tmp_path / "m.pgm", PIXELS)
    grid = load_map(write_yaml(tmp_path / "m.yaml", resolution=0.1, origin=[-3, 2.5, 0.25]))
    assert grid.resolution == 0.1 and grid.origin == (-3.0, 2.5, 0.25)


# --------------------------------------------------------------------------- saving


@pytest.mark.parametrize("image_format", ["pgm", "png", "bmp"])
def test_trinary_round_trip(tmp_path, image_format):
    rng = np.random.default_rng(7)
    data = rng.choice(np.array([0, 100, -1], dtype=np.int8), size=(23, 31))
    grid = OccupancyGrid(data, 0.037, (-12.5, 3.125, 0.7), "original")
    save_map(grid, tmp_path / "saved.yaml", image_format=image_format)
    loaded = load_map(tmp_path / "saved.yaml")
    np.testing.assert_array_equal(loaded.data, data)
    assert loaded.resolution == grid.resolution and loaded.origin == grid.origin
    assert loaded.name == "saved"
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"saved.{image_format}", "saved.yaml"]


def test_saved_files_follow_map_saver(tmp_path):
    grid = OccupancyGrid(np.array([[0, 100], [-1, 0]]), 0.05, (1.0, 2.0, 0.0))
    save_map(grid, tmp_path / "m.yaml")
    meta = yaml.safe_load((tmp_path / "m.yaml").read_text())
    assert meta == {
        "image": "m.pgm",
        "resolution": 0.05,
        "origin": [1.0, 2.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
        "mode": "trinary",
    }
    raw = (tmp_path / "m.pgm").read_bytes()
    assert raw.startswith(b"P5") and raw.endswith(bytes([205, 254, 254, 0]))  # top row first


def test_save_thresholds_intermediate_values(tmp_path):
    grid = OccupancyGrid(np.array([[0, 1, 64, 65, 99, 100, -1]]), 0.05)
    save_map(grid, tmp_path / "m.yaml")
    np.testing.assert_array_equal(
        load_map(tmp_path / "m.yaml").data, [[0, -1, -1, 100, 100, 100, -1]]
    )


def test_save_overwrites_existing_files(tmp_path):
    save_map(OccupancyGrid(np.zeros((3, 3)), 0.05), tmp_path / "m.yaml")
    save_map(OccupancyGrid(np.full((2, 4), 100), 0.1), tmp_path / "m.yaml")
    grid = load_map(tmp_path / "m.yaml")
    assert grid.data.shape == (2, 4) and grid.resolution == 0.1 and (grid.data == 100).all()


@pytest.mark.parametrize(
    ("target", "image_format"), [("m.yaml", "jpg"), ("m.pgm", "pgm"), ("missing/m.yaml", "pgm")]
)
def test_save_errors(tmp_path, target, image_format):
    path = tmp_path / target
    with pytest.raises(MapError, match=re.escape(f"Map file {path}: ")):
        save_map(OccupancyGrid(np.zeros((2, 2)), 0.05), path, image_format=image_format)


def test_save_writes_shared_files_atomically(tmp_path):
    # save_map writes through pegame.files.write_atomic: files readable by all, and a
    # failed write leaves no temporary file behind.
    save_map(OccupancyGrid(np.zeros((2, 2)), 0.05), tmp_path / "ok.yaml")
    assert {(p.name, p.stat().st_mode & 0o777) for p in tmp_path.iterdir()} == {
        ("ok.pgm", 0o644),
        ("ok.yaml", 0o644),
    }
    (tmp_path / "dir.yaml").mkdir()  # the YAML cannot replace a directory
    with pytest.raises(MapError, match="cannot write"):
        save_map(OccupancyGrid(np.zeros((2, 2)), 0.05), tmp_path / "dir.yaml")
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "dir.pgm",
        "dir.yaml",
        "ok.pgm",
        "ok.yaml",
    ]


# --------------------------------------------------------------------------- frames


@pytest.mark.parametrize(
    "origin", [(0.0, 0.0, 0.0), (-4.2, 7.1, 0.0), (1.3, -2.0, 0.6), (0.5, 0.5, -2.9)]
)
def test_cell_to_world_and_back(origin):
    grid = OccupancyGrid(np.zeros((40, 50)), 0.05, origin)
    rng = np.random.default_rng(3)
    rows, cols = rng.integers(-10, 60, size=(2, 200))
    np.testing.assert_array_equal(grid.world_to_cell(*grid.cell_to_world(rows, cols)), (rows, cols))
    assert grid.world_to_cell(*grid.cell_to_world(3, 4)) == (3, 4)


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (2.0, -1.0, 1.1)])
def test_world_to_cell_and_back_stays_within_the_cell(origin):
    grid = OccupancyGrid(np.zeros((40, 50)), 0.05, origin)
    rng = np.random.default_rng(4)
    x, y = rng.uniform(-3, 3, size=(2, 500))
    cx, cy = grid.cell_to_world(*grid.world_to_cell(x, y))
    c, s = math.cos(origin[2]), math.sin(origin[2])
    along, across = c * (x - cx) + s * (y - cy), -s * (x - cx) + c * (y - cy)
    assert np.all(np.abs(along) <= 0.025 + 1e-12) and np.all(np.abs(across) <= 0.025 + 1e-12)


def test_loaded_rows_run_up_in_y(tmp_path):
    write_p5(tmp_path / "m.pgm", PIXELS)
    grid = load_map(write_yaml(tmp_path / "m.yaml", origin=[10.0, 20.0, 0.0]))
    assert grid.is_free(10.025, 20.025)  # bottom-left pixel 255: free
    assert not grid.is_free(10.025, 20.075)  # top-left pixel 0: occupied


# --------------------------------------------------------------------------- bad input


def yaml_text(text: str):
    def make(tmp_path: Path) -> Path:
        write_p5(tmp_path / "m.pgm", PIXELS)
        path = tmp_path / "m.yaml"
        path.write_text(text)
        return path

    return make


def yaml_keys(**keys):
    def make(tmp_path: Path) -> Path:
        write_p5(tmp_path / "m.pgm", PIXELS)
        return write_yaml(tmp_path / "m.yaml", **keys)

    return make


def image_bytes(suffix: str, data: bytes):
    def make(tmp_path: Path) -> Path:
        (tmp_path / f"m.{suffix}").write_bytes(data)
        return write_yaml(tmp_path / "m.yaml", image=f"m.{suffix}")

    return make


def gif_image(tmp_path: Path) -> Path:
    Image.fromarray(PIXELS).save(tmp_path / "m.gif")
    return write_yaml(tmp_path / "m.yaml", image="m.gif")


BASE = "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"

BAD_MAPS = {
    "missing yaml": (lambda tmp_path: tmp_path / "m.yaml", "does not exist"),
    "invalid yaml": (yaml_text("image: [m.pgm\nresolution: 0.05\n"), "not valid YAML"),
    "yaml list": (yaml_text("- image\n- resolution\n"), "mapping"),
    "empty yaml": (yaml_text(""), "mapping"),
    "missing image": (yaml_text("resolution: 0.05\norigin: [0, 0, 0]\n"), "'image' is missing"),
    "missing resolution": (
        yaml_text("image: m.pgm\norigin: [0, 0, 0]\n"),
        "'resolution' is missing",
    ),
    "missing origin": (yaml_text("image: m.pgm\nresolution: 0.05\n"), "'origin' is missing"),
    "image not a string": (yaml_keys(image=3), "'image'"),
    "empty image": (yaml_keys(image=""), "'image'"),
    "resolution string": (yaml_keys(resolution="0.05"), "'resolution' must be a number"),
    "resolution bool": (yaml_keys(resolution=True), "'resolution' must be a number"),
    "resolution zero": (yaml_keys(resolution=0), "'resolution' must be finite and > 0"),
    "resolution negative": (yaml_keys(resolution=-0.05), "'resolution' must be finite"),
    "resolution nan": (
        yaml_text("image: m.pgm\nresolution: .nan\norigin: [0, 0, 0]\n"),
        "'resolution' must be finite",
    ),
    "resolution inf": (
        yaml_text("image: m.pgm\nresolution: .inf\norigin: [0, 0, 0]\n"),
        "'resolution' must be finite",
    ),
    "origin two numbers": (yaml_keys(origin=[0, 0]), "'origin' must be 3 finite numbers"),
    "origin four numbers": (yaml_keys(origin=[0, 0, 0, 0]), "'origin'"),
    "origin string item": (yaml_keys(origin=[0, "a", 0]), "'origin'"),
    "origin scalar": (yaml_keys(origin=0.0), "'origin'"),
    "origin nan": (yaml_text("image: m.pgm\nresolution: 0.05\norigin: [0, .nan, 0]\n"), "'origin'"),
    "negate two": (yaml_keys(negate=2), "'negate'"),
    "negate string": (yaml_keys(negate="maybe"), "'negate'"),
    "occupied above one": (yaml_keys(occupied_thresh=1.5), "'occupied_thresh' must lie in"),
    "free below zero": (yaml_keys(free_thresh=-0.1), "'free_thresh' must lie in"),
    "threshold string": (yaml_keys(free_thresh="low"), "'free_thresh' must be a number"),
    "free above occupied": (yaml_keys(free_thresh=0.7, occupied_thresh=0.6), "smaller than"),
    "free equals occupied": (yaml_keys(free_thresh=0.5, occupied_thresh=0.5), "smaller than"),
    "unknown mode": (yaml_keys(mode="binary"), "trinary, scale and raw"),
    "mode not a string": (yaml_keys(mode=1), "unknown mode"),
    "missing image file": (yaml_text(BASE.replace("m.pgm", "other.pgm")), "does not exist"),
    "image is a directory": (yaml_text(BASE.replace("m.pgm", ".")), "does not exist"),
    "garbage image": (image_bytes("pgm", b"not an image at all"), "not a readable image"),
    "truncated pgm": (image_bytes("pgm", b"P5\n4 4\n255\n\x00\x01"), "corrupt"),
    "16-bit pgm": (image_bytes("pgm", b"P5\n2 1\n65535\n\x00\x01\xff\xff"), "pixel mode"),
    "gif image": (gif_image, "GIF format; use PGM, PNG or BMP"),
}


@pytest.mark.parametrize(("make", "problem"), BAD_MAPS.values(), ids=BAD_MAPS.keys())
def test_bad_input_raises_map_error_naming_the_file(tmp_path, make, problem):
    path = make(tmp_path)
    with pytest.raises(MapError) as info:
        load_map(path)
    message = str(info.value)
    assert message.startswith(f"Map file {path}: ")
    assert problem in message
    assert "\n" not in message


# --------------------------------------------------------------------------- paper maps

ROBOT_RADIUS = 0.25
PAPER_MAPS = {  # name: (width, height) in cells, free-standing obstacles
    "hall": ((370, 330), 0),
    "enclosed": ((330, 330), 13),
    "brick": ((400, 300), 9),
}


@pytest.fixture(scope="module", params=PAPER_MAPS)
def paper_map(request) -> OccupancyGrid:
    return load_map(MAPS_DIR / f"{request.param}.yaml")


def test_paper_map_size_and_frame(paper_map):
    (width, height), _ = PAPER_MAPS[paper_map.name]
    assert (paper_map.width, paper_map.height) == (width, height)
    assert paper_map.resolution == 0.05 and paper_map.origin == (0.0, 0.0, 0.0)
    assert 15.0 <= paper_map.width * 0.05 <= 20.0 and 15.0 <= paper_map.height * 0.05 <= 20.0
    assert set(np.unique(paper_map.data)) <= {-1, 0, 100}


def test_paper_map_outer_wall_is_closed_and_thick(paper_map):
    data = paper_map.data
    ring = np.concatenate([data[0], data[-1], data[:, 0], data[:, -1]])
    assert not np.any(ring == 0)
    to_unknown = ndimage.distance_transform_edt(data != -1) * paper_map.resolution
    assert to_unknown[data == 0].min() > 0.15


def test_paper_map_free_space_is_connected_for_the_robot(paper_map):
    k = math.ceil(ROBOT_RADIUS / paper_map.resolution)
    yy, xx = np.mgrid[-k : k + 1, -k : k + 1]
    disc = np.hypot(xx, yy) <= ROBOT_RADIUS / paper_map.resolution
    reachable = ~ndimage.binary_dilation(paper_map.blocked, disc, border_value=1)
    _, regions = ndimage.label(reachable)
    assert regions == 1
    uncovered = paper_map.free & ~ndimage.binary_dilation(reachable, disc)
    labels, n = ndimage.label(uncovered, np.ones((3, 3)))
    assert n == 0 or np.bincount(labels.ravel())[1:].max() <= 12  # corner slivers only


def test_paper_map_free_standing_obstacles(paper_map):
    _, expected = PAPER_MAPS[paper_map.name]
    labels, n = ndimage.label(paper_map.data == 100, np.ones((3, 3)))
    near_outside = ndimage.binary_dilation(paper_map.data == -1, np.ones((3, 3)))
    outer_walls = np.count_nonzero(np.unique(labels[near_outside]))
    assert n - outer_walls == expected


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-3.2, 1.7, 0.0), (1.1, -0.4, 0.9)])
def test_world_to_cell_of_scalars_equals_that_of_arrays(origin):
    grid = OccupancyGrid(np.zeros((20, 30), dtype=np.int8), 0.05, origin)
    rng = np.random.default_rng(3)
    xs, ys = rng.uniform(-5, 5, 2000), rng.uniform(-5, 5, 2000)
    xs[:100], ys[:100] = np.round(xs[:100] / 0.05) * 0.05, np.round(ys[:100] / 0.05) * 0.05  # edges
    rows, cols = grid.world_to_cell(xs, ys)
    scalar = [grid.world_to_cell(float(x), float(y)) for x, y in zip(xs, ys)]
    assert scalar == list(zip(rows.tolist(), cols.tolist()))
    assert all(type(v) is int for v in scalar[0])


def test_per_grid_builds_once_per_grid_and_key():
    calls = []

    def build(grid):
        calls.append(grid)
        return np.zeros(1)

    one, two = OccupancyGrid(np.zeros((3, 3)), 0.1), OccupancyGrid(np.zeros((3, 3)), 0.1)
    first = per_grid(one, ("test", 1), build)
    assert per_grid(one, ("test", 1), build) is first and calls == [one]
    assert per_grid(one, ("test", 2), build) is not first
    assert per_grid(two, ("test", 1), build) is not first
    assert calls == [one, one, two]


def test_per_grid_cache_lives_and_dies_with_its_grid():
    grid = OccupancyGrid(np.zeros((3, 3)), 0.1)
    held = per_grid(grid, ("test",), lambda g: [g])  # the cached object refers to its grid
    for copied in (pickle.loads(pickle.dumps(grid)), copy.deepcopy(grid)):
        assert per_grid(copied, ("test",), lambda g: [g])[0] is copied  # rebuilt, not copied
    alive = weakref.ref(grid)
    del grid, held
    gc.collect()
    assert alive() is None


@pytest.mark.parametrize("yaw", [0.0, 0.7, -2.9])
def test_cell_centres_are_cell_to_world_bit_for_bit(yaw):
    grid = OccupancyGrid(np.zeros((37, 53), dtype=np.int8), 0.05, (1.3, -2.1, yaw))
    cells = np.arange(37 * 53)
    expected = np.stack(grid.cell_to_world(*np.divmod(cells, 53)), axis=-1)
    assert np.array_equal(cell_centres(cells, grid.width, grid.kernel_frame), expected)
