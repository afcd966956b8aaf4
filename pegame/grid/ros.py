"""ROS map_server map files: :func:`load_map` and :func:`save_map` of an OccupancyGrid.

Map files use the ROS map_server format: a YAML file with the keys

- ``image``: the image file, relative to the YAML file's directory or absolute (required);
- ``resolution``: cell edge length in metres per pixel, finite and > 0 (required);
- ``origin``: ``[x, y, yaw]`` (m, m, rad), the pose of the image's lower-left pixel
  (required);
- ``negate``: 0/1 or a bool; swaps the meaning of white and black (default 0);
- ``occupied_thresh`` and ``free_thresh``: in [0, 1] with free_thresh < occupied_thresh
  (defaults 0.65 and 0.196);
- ``mode``: ``trinary`` (default), ``scale`` or ``raw``.

Other keys are ignored. The image is an 8-bit PGM (plain P2 or binary P5), PNG or BMP.
Colour pixels are reduced to the mean of their colour channels, v in [0, 255]; an alpha
channel is never averaged in. Image row 0 is the top (highest y), so it becomes the grid's
last row. With shade s = 255 - v when ``negate`` is set and s = v otherwise, each pixel's
occupancy probability is p = (255 - s) / 255 (dark = occupied unless negated), and:

- ``trinary``: p > occupied_thresh -> 100; p < free_thresh -> 0; otherwise -1.
- ``scale``: the same two thresholds; otherwise -1 for a fully transparent pixel
  (alpha 0) and else ``int(1 + 98 * (p - free_thresh) / (occupied_thresh - free_thresh))``,
  a value in [1, 99], exactly as ROS 1 map_server computes it.
- ``raw``: the cell value is int(s) (so 0..100 are used as they are); map_server would
  wrap values above 127 into negative int8, here every value above 100 becomes -1.

Two deliberate differences from ROS 1 map_server: alpha is not averaged into the grey
value in trinary mode (map_server does, which turns opaque grey 205 into free), and
palette images are reduced by their palette colours, not their indices.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from io import BytesIO
from pathlib import Path
from typing import Any, TypeGuard

import numpy as np
import yaml
from PIL import Image

from pegame.errors import MapError
from pegame.files import write_atomic
from pegame.grid.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

MAP_MODES = ("trinary", "scale", "raw")
DEFAULT_OCCUPIED_THRESH = 0.65
DEFAULT_FREE_THRESH = 0.196

# Pixel values save_map writes (ROS map_saver's): free, occupied and unknown.
FREE_SHADE = 254
OCCUPIED_SHADE = 0
UNKNOWN_SHADE = 205
# save_map writes a cell as occupied when its value is at least this (map_saver's default).
SAVE_OCCUPIED_VALUE = 65

_READ_FORMATS = ("PPM", "PNG", "BMP")  # Pillow's names; PPM is Netpbm, PGM P2/P5 included
_SAVE_FORMATS = {"pgm": "PPM", "png": "PNG", "bmp": "BMP"}
_PIXEL_MODES = ("1", "L", "LA", "P", "PA", "RGB", "RGBA")
_DECODE_ERRORS = (OSError, ValueError, SyntaxError, EOFError, Image.DecompressionBombError)


@dataclass(frozen=True)
class _MapSpec:
    """A validated map YAML; fields as in the module docstring, image as a resolved path."""

    image: Path
    resolution: float
    origin: tuple[float, float, float]
    negate: bool
    occupied_thresh: float
    free_thresh: float
    mode: str


def load_map(yaml_path: str | os.PathLike) -> OccupancyGrid:
    """Load a ROS map_server map (YAML plus image) as an OccupancyGrid.

    Semantics are in the module docstring. The grid's name is the YAML file's stem.
    Raises MapError, naming the file and the problem, when the YAML is missing or
    invalid (not a mapping, a required key missing, a value of the wrong type or out of
    range, an unknown mode) or the image is missing, unsupported or corrupt.
    """
    path = Path(yaml_path)
    spec = _read_spec(path)
    grey, alpha = _read_image(spec.image, path)
    if grey.dtype == np.uint8:
        # A grey image: one value per grey level, looked up (a large map's pixels would
        # otherwise pass through several float arrays of 8 bytes each).
        values = _occupancy(np.arange(256, dtype=float), None, spec)[grey]
    else:
        values = _occupancy(grey, alpha, spec)
    return OccupancyGrid(np.flipud(values), spec.resolution, spec.origin, name=path.stem)


def save_map(grid: OccupancyGrid, yaml_path: str | os.PathLike, image_format: str = "pgm") -> None:
    """Write ``grid`` as a trinary ROS map: the image, then the YAML at ``yaml_path``.

    The image is ``<yaml stem>.<image_format>`` (pgm = binary P5, png or bmp) next to the
    YAML. Cells equal to 0 are written 254 (free), cells >= 65 are written 0 (occupied,
    as ROS map_saver does) and all others, unknown included, 205. The YAML holds the
    grid's resolution and origin, negate 0, occupied_thresh 0.65, free_thresh 0.196 and
    mode trinary, so load_map gives back a grid of 0/100/-1 values exactly. Each file is
    written atomically (:func:`pegame.files.write_atomic`: a temporary file in the same
    directory, moved into place with os.replace). Raises MapError for a bad image_format
    or a file that cannot be written.
    """
    yaml_path = Path(yaml_path)
    pillow_format = _SAVE_FORMATS.get(image_format)
    if pillow_format is None:
        raise _fail(yaml_path, f"cannot save the image as {image_format!r}; use pgm, png or bmp.")
    image_path = yaml_path.with_suffix(f".{image_format}")
    if image_path == yaml_path:
        raise _fail(yaml_path, f"the YAML file needs a suffix other than .{image_format}.")
    _check_saveable(grid, yaml_path)
    shades = np.full(grid.data.shape, UNKNOWN_SHADE, dtype=np.uint8)
    shades[grid.data >= SAVE_OCCUPIED_VALUE] = OCCUPIED_SHADE
    shades[grid.data == FREE] = FREE_SHADE
    image = BytesIO()
    Image.fromarray(np.flipud(shades)).save(image, format=pillow_format)
    meta = {
        "image": image_path.name,
        "resolution": float(grid.resolution),
        "origin": list(grid.origin),
        "negate": 0,
        "occupied_thresh": DEFAULT_OCCUPIED_THRESH,
        "free_thresh": DEFAULT_FREE_THRESH,
        "mode": "trinary",
    }
    text = yaml.safe_dump(meta, sort_keys=False, default_flow_style=None)
    for path, data in ((image_path, image.getvalue()), (yaml_path, text.encode("utf-8"))):
        try:
            write_atomic(path, data)
        except OSError as exc:
            raise _fail(yaml_path, f"cannot write {path} ({exc.strerror or exc}).") from exc


def _fail(path: Path, problem: str) -> MapError:
    return MapError(f"Map file {path}: {problem}")


def _is_number(value: Any) -> TypeGuard[float]:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _read_yaml(path: Path) -> dict:
    if not path.exists():
        raise _fail(path, "does not exist.")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise _fail(path, f"cannot be read ({exc}).") from exc
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise _fail(path, f"is not valid YAML ({' '.join(str(exc).split())}).") from exc
    if not isinstance(doc, dict):
        raise _fail(path, f"must hold a YAML mapping of map keys, not {type(doc).__name__}.")
    return doc


def _number(doc: dict, key: str, path: Path, default: float | None = None) -> float:
    value = doc.get(key, default)
    if not _is_number(value):
        raise _fail(path, f"key '{key}' must be a number, got {value!r}.")
    return float(value)


def _read_spec(path: Path) -> _MapSpec:
    doc = _read_yaml(path)
    for key in ("image", "resolution", "origin"):
        if key not in doc:
            raise _fail(
                path, f"key '{key}' is missing; a ROS map YAML needs image, resolution and origin."
            )
    image = doc["image"]
    if not isinstance(image, str) or not image.strip():
        raise _fail(path, f"key 'image' must be a non-empty file name, got {image!r}.")
    resolution = _number(doc, "resolution", path)
    if not (math.isfinite(resolution) and resolution > 0):
        raise _fail(path, f"key 'resolution' must be finite and > 0 (m/cell), got {resolution}.")
    origin = doc["origin"]
    if not (
        isinstance(origin, list)
        and len(origin) == 3
        and all(_is_number(v) and math.isfinite(v) for v in origin)
    ):
        raise _fail(path, f"key 'origin' must be 3 finite numbers [x, y, yaw], got {origin!r}.")
    negate = doc.get("negate", 0)
    if not (isinstance(negate, int) and negate in (0, 1)):
        raise _fail(path, f"key 'negate' must be 0, 1, true or false, got {negate!r}.")
    occupied = _number(doc, "occupied_thresh", path, DEFAULT_OCCUPIED_THRESH)
    free = _number(doc, "free_thresh", path, DEFAULT_FREE_THRESH)
    for key, value in (("occupied_thresh", occupied), ("free_thresh", free)):
        if not 0.0 <= value <= 1.0:
            raise _fail(path, f"key '{key}' must lie in [0, 1], got {value}.")
    if free >= occupied:
        raise _fail(
            path, f"free_thresh ({free}) must be smaller than occupied_thresh ({occupied})."
        )
    mode = doc.get("mode", "trinary")
    if not (isinstance(mode, str) and mode in MAP_MODES):
        raise _fail(path, f"unknown mode {mode!r}; the allowed modes are trinary, scale and raw.")
    return _MapSpec(
        image=path.parent / image,  # an absolute image path replaces the directory
        resolution=resolution,
        origin=(float(origin[0]), float(origin[1]), float(origin[2])),
        negate=bool(negate),
        occupied_thresh=occupied,
        free_thresh=free,
        mode=mode,
    )


def _read_image(image_path: Path, yaml_path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Image -> (grey (H, W), alpha (H, W) uint8 or None): grey is the uint8 pixels of
    a grey image (alpha None), else the float mean of the colour channels.

    Rows are in image order (row 0 = top).
    """
    if not image_path.is_file():
        raise _fail(yaml_path, f"image file {image_path} does not exist or is not a file.")
    try:
        image = Image.open(image_path)
    except _DECODE_ERRORS as exc:
        raise _fail(yaml_path, f"image {image_path} is not a readable image ({exc}).") from exc
    with image:
        if image.format not in _READ_FORMATS:
            raise _fail(
                yaml_path,
                f"image {image_path} is in {image.format} format; use PGM, PNG or BMP.",
            )
        if image.mode not in _PIXEL_MODES:
            raise _fail(
                yaml_path,
                f"image {image_path} has pixel mode {image.mode}; only 8-bit grey, "
                "palette and RGB(A) images are supported.",
            )
        try:
            converted = _as_8bit_channels(image)
            pixels = np.asarray(converted)
        except _DECODE_ERRORS as exc:
            raise _fail(yaml_path, f"image {image_path} is corrupt ({exc}).") from exc
        has_alpha = converted.mode.endswith("A")
    if pixels.ndim == 2:
        return pixels.astype(np.uint8, copy=False), None
    colour = pixels[..., :-1] if has_alpha else pixels
    grey = colour.sum(axis=2, dtype=float) / colour.shape[2]
    return grey, pixels[..., -1] if has_alpha else None


def _as_8bit_channels(image: Image.Image) -> Image.Image:
    """Bilevel -> L and palette -> RGB or RGBA; L, LA, RGB and RGBA are kept."""
    if image.mode == "1":
        return image.convert("L")
    if image.mode in ("P", "PA"):
        transparent = image.mode == "PA" or "transparency" in image.info
        return image.convert("RGBA" if transparent else "RGB")
    return image


def _occupancy(grey: np.ndarray, alpha: np.ndarray | None, spec: _MapSpec) -> np.ndarray:
    """Per-pixel cell values (int8, image row order) for the spec's mode and thresholds."""
    shade = 255.0 - grey if spec.negate else grey
    if spec.mode == "raw":
        value = np.floor(shade)
        return np.where(value > OCCUPIED, UNKNOWN, value).astype(np.int8)
    occ = (255.0 - shade) / 255.0
    if spec.mode == "scale":
        ratio = (occ - spec.free_thresh) / (spec.occupied_thresh - spec.free_thresh)
        between = np.floor(1.0 + 98.0 * ratio)
        if alpha is not None:
            between = np.where(alpha == 0, UNKNOWN, between)
    else:
        between = np.full(occ.shape, float(UNKNOWN))
    value = np.where(
        occ > spec.occupied_thresh, OCCUPIED, np.where(occ < spec.free_thresh, FREE, between)
    )
    return value.astype(np.int8)


def _check_saveable(grid: OccupancyGrid, yaml_path: Path) -> None:
    res = grid.resolution
    if not (math.isfinite(res) and res > 0 and all(math.isfinite(v) for v in grid.origin)):
        raise _fail(
            yaml_path,
            f"cannot save a grid with resolution {res} and origin {grid.origin}; the "
            "resolution must be finite and > 0 and the origin finite.",
        )
