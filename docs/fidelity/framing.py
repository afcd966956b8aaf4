"""Why ``detector=person`` finds nothing at the paper's pi/8 tilt: what the camera frames.

A pinhole camera of horizontal FOV ``fov`` on a W x H image sees up to the vertical half
angle atan(tan(fov / 2) H / W) above its axis; pitched down by ``tilt``, the highest point
it frames at horizontal range r (m) is h + r tan(half - tilt) above the floor, h the
camera's height. Read from sim=pybullet's defaults (camera height, tilt, image size), the
paper's FOV (pi/3, paper_conditions) and the person's height and hip
(pegame_pybullet.bodies, .person), and from the committed profiles of the person
detector (the visible fraction of its body in the frames of the reference, tilted and
level). :func:`values` gives the README's quoted figures.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

from pegame.detectors.profile import profile_names
from pegame_pybullet.bodies import EVADER_HEIGHT
from pegame_pybullet.person import HIP_HEIGHT
from pegame_pybullet.sim import PybulletSimulator

FOV = math.pi / 3  # rad, the paper's (paper_conditions' camera.fov)


def top_of_view(distance: float, tilt: float, width: int, height: int, camera: float) -> float:
    """Height (m) above the floor of the highest point framed ``distance`` m away."""
    half = math.atan(math.tan(0.5 * FOV) * height / width)
    return camera + distance * math.tan(half - tilt)


def profile_rows(path: Path) -> dict[tuple[str, str], tuple[int, float]]:
    with path.open(newline="") as handle:
        return {
            (r["variable"], r["low"]): (int(r["frames"]), float(r["p_detect"] or "nan"))
            for r in csv.DictReader(handle)
        }


def values() -> dict[str, str]:
    """The README's figures on the person detector's framing at the paper's tilt."""
    config = PybulletSimulator.Config()
    tilt, camera = config.camera_tilt, config.camera_height
    top = lambda r, t=tilt: top_of_view(r, t, config.width, config.height, camera)  # noqa: E731
    half_minus_tilt = top(1.0) - camera  # m of height per m of range
    names = profile_names()
    tilted = profile_rows(names["person_paper_tilt"])
    level = profile_rows(names["person_level"])
    seen = sum(tilted[("range", low)][0] for low in ("0", "1", "2", "3", "4"))
    found = round(sum(n * p for (v, _), (n, p) in tilted.items() if v == "range" and n))
    low_visible = tilted[("visible", "0")][0] + tilted[("visible", "0.1")][0]
    # the nearest range at which a level camera frames the whole person
    whole = (EVADER_HEIGHT - camera) / (top(1.0, 0.0) - camera)
    return {
        "tilt_top_1m": f"{top(1.0):.2f} m",
        "tilt_top_5m": f"{top(5.0):.2f} m",
        "tilt_hip_range": f"{(HIP_HEIGHT - camera) / half_minus_tilt:.0f} m",
        "level_whole_range": f"{whole:.1f} m",
        "person_tilt_found": f"{found} of {seen}",
        "person_tilt_low_visible": f"{low_visible} of {seen}",
        "person_level_whole": f"{100 * level[('visible', '0.6')][1]:.0f}%",
        "person_level_far": f"{100 * level[('range', '4')][1]:.0f}%",
    }
