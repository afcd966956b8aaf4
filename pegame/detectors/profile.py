"""A detection profile identified from the 3D pipeline, played by the grid's perception model.

``python -m pegame_vision.profile`` measures a 3D detector (``detector=vision`` or
``detector=person`` on rendered PyBullet frames) against the simulator's segmentation and
writes its marginal tables: the chance to detect a seen evader per bin of range (m),
bearing (rad, absolute), visible fraction of the body and lateral relative speed (m/s),
each with its frame count, and the position error in the line of sight's frame (m). Every
number in it is a 3D measurement; none comes from the paper's Table 1 or from grid-vs-3D
differences. ``detector.profile=NAME`` (``<detector>_<camera>``, a file
``<camera>/<detector>.csv`` of pegame-vision's ``profiles``) or ``=PATH`` makes the oracle
detector draw each seen evader's detection from it.

Combining the marginals: naive Bayes (e.g. Hastie, Tibshirani & Friedman, *The Elements
of Statistical Learning*, 2nd ed., Sec. 6.6.3). If the variables are independent given
the outcome (found or missed), the odds of a detection given all four are the overall
odds times each variable's likelihood ratio, and a variable's likelihood ratio in a bin is
that bin's odds over the overall odds; in log-odds,

    logit p(x) = logit p + sum_v [logit p_v(bin_v(x)) - logit p],

p the overall rate over the seen frames and p_v the bin's rate. This is the product of
per-variable factors normalised by the overall rate, on the odds scale, where it stays a
probability, and it needs nothing the marginal tables do not hold (a joint table of four
variables would leave most of its cells empty at the few thousand frames a profile
has). Its error is where the variables are dependent given the outcome (range and
visible fraction are: a tilted camera frames less of a near body); the held-out check of
docs/fidelity measures it. The overall rate is Laplace's rule of succession,
(found + 1) / (frames + 2), and each bin's the m-estimate of Cestnik (1990, "Estimating
probabilities: a crucial task in machine learning", ECAI), (found + m p) / (frames + m)
with m = :data:`PRIOR_FRAMES`: a bin of all hits or all misses has finite odds, and a bin
of few frames is pulled towards the overall rate (no factor), not towards one half. A bin
without frames, and a lateral speed not yet known (the game's first frame), contribute no
factor; a value outside the bins falls in the nearest one.

What the grid knows of the four, on the frames on which any part of the evader's body is
in view (:func:`pegame.visibility.body_in_view`: the profile's frames are those on which
the reference sees evader pixels, its centre out of the image on some): the range and
bearing from the camera's pose to the evader's centre; the visible fraction
1 - :func:`pegame.detectors.perception.hidden_fraction`
(the silhouette points across the line of sight, :data:`pegame.visibility.SILHOUETTE`; the
3D one also counts the body's height outside the image, which the range factor carries
where the camera is tilted); the evader's speed across the line of sight relative to the
camera, from the poses of the detector's previous call (one control tick before, as the
profile's frames are).

The position error: a detection is placed at the evader's centre moved by the profile's
mean error along the line of sight (its bias; positive beyond the centre) plus Gaussian
errors of its along and across standard deviations (m).
The latency is not the profile's: the 3D simulator waits for its detector, so the CPU time
the profile measured (``cpu_ms``) delays nothing in a game's time, and both simulators
deliver ``detector.latency`` s after capture.
"""

from __future__ import annotations

import csv
import importlib.util
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pegame.errors import ConfigError

#: the profile's variables, in the order :meth:`DetectionProfile.probability` takes them
VARIABLES = ("range", "bearing", "visible", "lateral_speed")
#: m of the bins' m-estimate: the overall rate counts as this many frames in every bin
PRIOR_FRAMES = 2.0
#: rows of the position error (m) in the line of sight's frame
ERRORS = ("error_along_mean_m", "error_along_std_m", "error_across_std_m")


def profiles_dir() -> Path | None:
    """pegame-vision's committed profiles (``profiles/<camera>/<detector>.csv`` in its
    package, installed with it), or None when pegame-vision is not installed."""
    spec = importlib.util.find_spec("pegame_vision")
    if spec is None or spec.origin is None:
        return None
    folder = Path(spec.origin).resolve().parent / "profiles"
    return folder if folder.is_dir() else None


def profile_names() -> dict[str, Path]:
    """Each committed profile's name, ``<detector>_<camera>``, and its file."""
    folder = profiles_dir()
    if folder is None:
        return {}
    files = sorted(p for p in folder.glob("*/*.csv") if not p.stem.endswith("_frames"))
    return {f"{p.stem}_{p.parent.name}": p for p in files}


def resolve(profile: str) -> Path:
    """The file of ``profile`` (a name of :func:`profile_names`, or a path to a profile's
    CSV); ConfigError naming the allowed values otherwise."""
    names = profile_names()
    if profile in names:
        return names[profile]
    path = Path(profile)
    if path.suffix == ".csv" and path.is_file():
        return path
    allowed = ", ".join(names) or "none installed (pegame-vision's profiles are not found)"
    raise ConfigError(
        f"Invalid value for 'detector.profile': {profile!r}. Allowed: null (no profile), a "
        f"profile name ({allowed}), or the path of a profile CSV written by "
        "python -m pegame_vision.profile."
    )


def _logit(p: float) -> float:
    return math.log(p / (1.0 - p))


@dataclass(frozen=True)
class DetectionProfile:
    """A profile's tables: per variable, its bins' (low, high) edges and log-odds offsets
    from the overall rate (0 for a bin without frames), the overall rate's log-odds, and the
    position error (m): the mean along the line of sight and the along and across stds."""

    bins: dict[str, tuple[tuple[float, float, float], ...]]
    base: float
    along_mean: float
    along_std: float
    across_std: float

    @classmethod
    def read(cls, path: Path) -> DetectionProfile:
        """The profile in ``path`` (the CSV of ``pegame_vision.profile``)."""
        with path.open(newline="") as handle:
            rows = list(csv.DictReader(handle))
        counts: dict[str, list[tuple[float, float, int, int]]] = {v: [] for v in VARIABLES}
        errors = dict.fromkeys(ERRORS, 0.0)
        for row in rows:
            name = row["variable"]
            if name in counts:
                frames = int(row["frames"])
                found = round(frames * float(row["p_detect"])) if frames else 0
                counts[name].append((float(row["low"]), float(row["high"]), frames, found))
            elif name in errors and row["p_detect"]:
                errors[name] = float(row["p_detect"])
        missing = [v for v in VARIABLES if not counts[v]]
        if missing:
            raise ConfigError(
                f"Invalid value for 'detector.profile': {str(path)!r} has no rows of "
                f"{', '.join(missing)}. Allowed: a profile CSV with rows of each of "
                f"{', '.join(VARIABLES)} (python -m pegame_vision.profile writes one)."
            )
        # every seen frame has a range: the range bins hold the overall rate
        seen = sum(c[2] for c in counts["range"])
        detected = sum(c[3] for c in counts["range"])
        overall = (detected + 1) / (seen + 2)
        base, m = _logit(overall), PRIOR_FRAMES
        bins = {
            v: tuple(
                (low, high, _logit((k + m * overall) / (n + m)) - base if n else 0.0)
                for low, high, n, k in counts[v]
            )
            for v in VARIABLES
        }
        return cls(bins, base, *(errors[e] for e in ERRORS))

    def probability(self, distance: float, bearing: float, visible: float, lateral: float) -> float:
        """The chance to detect an evader ``distance`` m away at ``bearing`` rad (either
        side) with a ``visible`` fraction of its body in view, moving ``lateral`` m/s across
        the line of sight relative to the camera (NaN: unknown, no factor)."""
        logit = self.base
        for variable, value in zip(VARIABLES, (distance, bearing, visible, lateral)):
            if math.isnan(value):
                continue
            table = self.bins[variable]
            # the bin holding the value; beyond the edges, the nearest bin
            offset = next((o for low, high, o in table if value < high), table[-1][2])
            logit += offset
        return 1.0 / (1.0 + math.exp(-logit))

    def position_error(self, rng: np.random.Generator) -> tuple[float, float]:
        """A position error (m) along and across the line of sight: two normal draws of
        ``rng``."""
        along, across = rng.normal(0.0, 1.0, 2)
        return (
            self.along_mean + self.along_std * float(along),
            self.across_std * float(across),
        )
