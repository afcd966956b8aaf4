"""The batched game's data as its numba kernels take it: the fixed numbers of a game
(:class:`World`, :class:`Rules`, built by :mod:`pegame.vector.game`) and the games'
changing state (:class:`BatchState`, arrays whose first axis is the game), with the
index constants of their columns. Units: SI, map frame.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

# the entries of ``rules.camera``: the oracle detector's camera numbers
from pegame.detectors.oracle import BODY_HEIGHT as BODY_HEIGHT
from pegame.detectors.oracle import CAMERA_HEIGHT as CAMERA_HEIGHT
from pegame.detectors.oracle import DETECTION_RANGE as DETECTION_RANGE
from pegame.detectors.oracle import FAR as FAR
from pegame.detectors.oracle import FOCAL as FOCAL
from pegame.detectors.oracle import FOV as FOV
from pegame.detectors.oracle import IMAGE_HEIGHT as IMAGE_HEIGHT
from pegame.detectors.oracle import IMAGE_WIDTH as IMAGE_WIDTH
from pegame.detectors.oracle import NEAR as NEAR
from pegame.detectors.perception import new_pipeline

# the columns of ``rules.bodies``: the grid simulator's move kernel's
from pegame.sims.grid import A_MAX as A_MAX
from pegame.sims.grid import ALPHA_MAX as ALPHA_MAX
from pegame.sims.grid import RADIUS as RADIUS
from pegame.sims.grid import V_MAX as V_MAX
from pegame.sims.grid import W_MAX as W_MAX

#: the roles' index in the role axes (World.masks), and a 1v1 game's agents' in the agent
#: axes (a team's agents are its pursuers, then its evaders)
PURSUER, EVADER = 0, 1
#: entries of ``rules.perception`` (the perception model's parts the batched game plays,
#: :mod:`pegame.detectors.perception`): the capture period (s), whether a rate sets it,
#: the latency (s), whether the pipeline runs (else each tick delivers its own capture),
#: whether the range or occlusion miss is on, miss_range_start (m, NaN: off),
#: miss_at_range, occlusion_miss; whether the independent miss or the depth noise is on
#: (each in-range capture then takes a (uniform, normal) pair of the detector's own
#: draws), miss_probability, range_noise (m), range_noise_growth (1/m), bearing_noise (rad),
#: burst_miss_fraction, burst_length (s), false_positive_rate (1/s)
PERIOD, RATED, LATENCY, PIPELINE, MISSES, MISS_START, MISS_AT_RANGE, OCCLUSION_MISS = range(8)
NOISY, MISS_PROBABILITY, RANGE_NOISE, NOISE_GROWTH, BEARING_NOISE = range(8, 13)
BURST_FRACTION, BURST_LENGTH, FALSE_POSITIVE_RATE = range(13, 16)
#: columns of ``state.noise``: the detector's uniform and normal of an in-range capture
#: (the independent miss and the depth noise), the 'bearing' part's error (rad), the
#: 'burst' part's uniform of a captured frame, and from FALSE_POSITIVE_DRAW on three
#: columns of the 'false_positive' part's uniforms, taken in row order (one per frame
#: without a detection, two more for a false positive)
MISS_DRAW, DEPTH_DRAW, BEARING_DRAW, BURST_DRAW, FALSE_POSITIVE_DRAW = range(5)
NOISE_COLUMNS = 7
#: columns of ``state.detection``: the box (px), the depth (m) and the map position (m)
BOX_X, BOX_Y, BOX_W, BOX_H, DEPTH, SEEN_X, SEEN_Y = range(7)
DETECTION_SIZE = 7
#: columns of ``state.tally`` (counts are exact in float64)
(
    TICKS,
    DETECTED,
    IN_VIEW,
    IN_LOSS,
    LOSS_START,
    FIRST_LOSS,
    LONGEST_LOSS,
    REACQUISITIONS,
    REACQUIRE_SUM,
    REACQUIRE_MAX,
    DISTANCE_SUM,
    PURSUER_PATH,
    EVADER_PATH,
    LAST_PX,
    LAST_PY,
    LAST_EX,
    LAST_EY,
) = range(17)
TALLY_SIZE = 17
#: columns of ``state.crew``, a team game's per-pursuer measures
#: (:class:`pegame.metrics.TeamMetrics`): ticks it detected some evader, its path (m), its
#: last position (m)
CREW_DETECTED, CREW_PATH, CREW_LAST_X, CREW_LAST_Y = range(4)
CREW_SIZE = 4

#: batches of at least this many games are spread over numba's threads (prange); below,
#: starting the threads costs more than it saves, most of all on a busy machine
PARALLEL_GAMES = 256


class World(NamedTuple):
    """The map as the kernels read it.

    blocked: the grid's blocked cells; frame: its ``kernel_frame`` as a float64 array (a
    tuple of mixed types cannot enter numba's parallel loops); masks: (2, H, W) the
    grid inflated by the pursuer's and the evader's radius (the simulator's collision
    masks); pooled, crop_x, crop_y, crop_frame: the crop's pooled map, robot-frame cell
    offsets (m) and its map-to-cell numbers (:class:`pegame.observe.crop.LocalCrop`, float64);
    crop_table: uint8 (H + 2 pad, W + 2 pad): the pooled map (1 blocked, 0 free)
    in a border of ``pad`` blocked cells wider than the crop's reach, the crop's look-up
    table; crop_centres: float64 (crop_cells,): the crop's cell centres along one axis
    (m; crop_x and crop_y are their grid); sight_values: bool (1 + H * W,): True (off
    the grid), then ``blocked`` flat, the line of sight's look-up table (``frame`` and
    it: :func:`pegame.visibility.sight.sight_tables`);
    extent: (x0, y0, 2 / width, 2 / height, diagonal) of the observations' normalisation
    (:func:`pegame.observe.features.extent_numbers`).
    """

    blocked: np.ndarray
    frame: np.ndarray
    masks: np.ndarray
    pooled: np.ndarray
    crop_x: np.ndarray
    crop_y: np.ndarray
    crop_frame: np.ndarray
    crop_table: np.ndarray
    crop_centres: np.ndarray
    sight_values: np.ndarray
    extent: np.ndarray


class Rules(NamedTuple):
    """The game's fixed numbers.

    bodies: (A, 5) float64 per agent (the pursuers, then the evaders): radius (m), v_max
    (m/s), w_max (rad/s), a_max (m/s^2), alpha_max (rad/s^2); camera: float64 (9,) as the constants
    FOV..CAMERA_HEIGHT (:func:`pegame.detectors.oracle.camera_numbers`); perception:
    float64 (16,) as the constants PERIOD..FALSE_POSITIVE_RATE; control_dt (s); substeps per
    control tick; decide_every: control ticks per decision; ticks: control ticks per game;
    pursuers, evaders: the team sizes P and E (1 and 1 in a 1v1 game).
    """

    bodies: np.ndarray
    camera: np.ndarray
    perception: np.ndarray
    control_dt: float
    substeps: int
    decide_every: int
    ticks: int
    pursuers: int
    evaders: int


class BatchState(NamedTuple):
    """The games' state. A game has A = P + E agents, its pursuers then its evaders, and
    Q = P * E detector pairs (pursuer i, evader j); per-game arrays have the game as first
    axis, per-member and per-pair ones a row per member or pair of each game in order
    (row ``game * E + j`` of evader j, ``game * P + i`` of pursuer i, ``game * Q + i * E +
    j`` of pair (i, j)), so that a 1v1 game's rows are the game's.

    Per game: poses (N, A, 3): (x, y, theta) per agent; velocities (N, A, 2): the current
    (v, w) of bodies with acceleration limits; commands (N, A, 2): this tick's (v, w)
    commands; steps (N,): control ticks played; handoffs (N,): a team game's handoffs.
    Per pair: detected: the current tick's detection; detection (., 7): its box, depth and
    position (columns BOX_X..SEEN_Y); in_view. Per pursuer: seen (., 3): time (s) and
    position of the last detection of its target evader (i mod E), for its observation,
    with has_seen; crew (., CREW_SIZE): a team game's per-pursuer measures. Per evader:
    tally (., TALLY_SIZE): the metrics' running sums (the pursuer nearest it as the
    pursuer); trackers: the pursuer tracking it, -1 none (a team game's handoffs);
    rewards: the ticks it was detected by some pursuer in the current env step.

    The perception pipeline, per pair, when it runs (delivered: detected and detection):
    pipeline (., DUE + K): each pair's (:func:`pegame.detectors.perception.new_pipeline`);
    captured and capture (., 7): the tick's own capture; in_flight_detected (., K) and
    in_flight (., K, 7): the results in flight by slot; draws (., D): each pair's range
    stream drawn ahead (the range and occlusion misses), drawn of them used; noise (., D,
    NOISE_COLUMNS): each pair's draws of the independent miss, the depth noise, the
    bearing noise, the bursts and the false positives drawn ahead (columns
    MISS_DRAW..FALSE_POSITIVE_DRAW), noise_drawn (., 4) of them used (the first two
    columns, the third, the fourth, the last three); bursting: each pair's burst chain
    (-1 undrawn, 0 between bursts, 1 in one).
    """

    poses: np.ndarray
    velocities: np.ndarray
    commands: np.ndarray
    steps: np.ndarray
    detected: np.ndarray
    detection: np.ndarray
    in_view: np.ndarray
    seen: np.ndarray
    has_seen: np.ndarray
    tally: np.ndarray
    rewards: np.ndarray
    pipeline: np.ndarray
    captured: np.ndarray
    capture: np.ndarray
    in_flight_detected: np.ndarray
    in_flight: np.ndarray
    draws: np.ndarray
    drawn: np.ndarray
    noise: np.ndarray
    noise_drawn: np.ndarray
    bursting: np.ndarray
    crew: np.ndarray
    trackers: np.ndarray
    handoffs: np.ndarray


def new_state(
    num_games: int,
    slots: int = 1,
    draws: int = 1,
    pursuers: int = 1,
    evaders: int = 1,
    noise: int = 1,
) -> BatchState:
    """Zeroed state for ``num_games`` games of ``pursuers`` against ``evaders``, ``slots``
    results in flight, ``draws`` range draws and ``noise`` noise draws per pair."""
    n, agents, pairs = num_games, pursuers + evaders, num_games * pursuers * evaders
    crew, members = num_games * pursuers, num_games * evaders
    return BatchState(
        np.zeros((n, agents, 3)),
        np.zeros((n, agents, 2)),
        np.zeros((n, agents, 2)),
        np.zeros(n, np.int64),
        np.zeros(pairs, np.bool_),
        np.zeros((pairs, DETECTION_SIZE)),
        np.zeros(pairs, np.bool_),
        np.zeros((crew, 3)),
        np.zeros(crew, np.bool_),
        np.zeros((members, TALLY_SIZE)),
        np.zeros(members),
        new_pipeline(pairs, slots),
        np.zeros(pairs, np.bool_),
        np.zeros((pairs, DETECTION_SIZE)),
        np.zeros((pairs, slots), np.bool_),
        np.zeros((pairs, slots, DETECTION_SIZE)),
        np.zeros((pairs, draws)),
        np.zeros(pairs, np.int64),
        np.zeros((pairs, noise, NOISE_COLUMNS)),
        np.zeros((pairs, 4), np.int64),
        np.full(pairs, -1, np.int64),
        np.zeros((crew, CREW_SIZE)),
        np.full(members, -1, np.int64),
        np.zeros(n),
    )
