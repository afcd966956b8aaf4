"""What the pursuer's camera gives in a batched game, per game: the oracle detector and
the ground truth in_view, from the kernels of the plugins they are.

The tests and float operations are the scalar code's own numba kernels, inlined here
into the loop over games: the line of sight and the point and body in view
(:func:`pegame.visibility.sight.point_in_view`, :func:`pegame.visibility.sight.
silhouette_in_view`), the hidden fraction
(:func:`pegame.detectors.perception.silhouette_hidden`), the range and occlusion miss
chance (:func:`pegame.detectors.perception.miss_chance`), the detection's geometry
(:func:`pegame.detectors.oracle.image`: bearing, depth, pinhole box, back-projection) and
the pipeline's schedule (:func:`pegame.detectors.perception.frame_due`,
:func:`pegame.detectors.perception.deliver_frame`). What is the batch's own is here:

- :func:`detect` is the oracle detector's capture
  (:class:`pegame.detectors.oracle.OracleDetector`) for the parts the batched game plays:
  the evader's centre in view and in the detection range, the range and occlusion misses
  drawn from each detector pair's 'range' stream drawn ahead (state.draws), the detection
  into the pair's rows of the state;
- :func:`sense` is the loop's ``_sense`` (each pair's detection, then in_view) with the
  pursuer observations' memory of the last detection; a detection goes through the
  perception model's pipeline (rate and latency) when it runs, the results in flight in
  the state's arrays.

``tests/vector/test_kernels.py`` and ``tests/envs`` compare them with the plain code.
Units: SI, map frame.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pegame.detectors.oracle import body_box, image
from pegame.detectors.perception import (
    burst_next,
    deliver_frame,
    frame_due,
    miss_chance,
    silhouette_hidden,
)
from pegame.numerics import hypot
from pegame.vector.state import (
    BEARING_DRAW,
    BEARING_NOISE,
    BOX_H,
    BOX_W,
    BOX_X,
    BOX_Y,
    BURST_DRAW,
    BURST_FRACTION,
    BURST_LENGTH,
    DEPTH,
    DEPTH_DRAW,
    DETECTION_RANGE,
    FALSE_POSITIVE_DRAW,
    FALSE_POSITIVE_RATE,
    FAR,
    FOV,
    LATENCY,
    MISS_AT_RANGE,
    MISS_DRAW,
    MISS_PROBABILITY,
    MISS_START,
    MISSES,
    NEAR,
    NOISE_GROWTH,
    NOISY,
    OCCLUSION_MISS,
    PERIOD,
    PIPELINE,
    RADIUS,
    RANGE_NOISE,
    RATED,
    SEEN_X,
    SEEN_Y,
    BatchState,
    Rules,
    World,
)
from pegame.visibility.sight import point_in_view, silhouette_in_view


@njit(cache=True, inline="always")
def detect(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    camera: np.ndarray,
    perception: np.ndarray,
    radius: float,
    cx: float,
    cy: float,
    ctheta: float,
    ex: float,
    ey: float,
    draws: np.ndarray,
    drawn: np.ndarray,
    noise: np.ndarray,
    noise_drawn: np.ndarray,
    detected: np.ndarray,
    detection: np.ndarray,
    pair: int,
) -> bool:
    """The oracle detector's capture of the evader at (ex, ey) by the camera at (cx, cy,
    ctheta) (m, rad; map frame) into ``detected`` and ``detection`` (rows ``pair``, the
    detector pair's; ``frame``, ``blocked``, ``values``: world.frame, world.blocked,
    world.sight_values; ``camera``: rules.camera, ``perception``: rules.perception,
    ``radius``: the evader's; a range or occlusion miss takes the next of the pair's
    ``draws``, counted in ``drawn``; with the independent miss or the depth noise on, an
    in-range capture takes the next (uniform, normal) pair of ``noise``, and with the
    bearing noise a detection the next bearing error, counted in ``noise_drawn``, in the
    order the oracle draws them). Returns whether the evader's centre is in view.
    (The functions here take the world's arrays, not the World: an inlined function
    given a NamedTuple pays a reference count per array.)"""
    near, far, fov = camera[NEAR], camera[FAR], camera[FOV]
    detected[pair] = False
    if not point_in_view(frame, blocked, values, near, far, fov, cx, cy, ctheta, ex, ey):
        return False
    distance = hypot(ex - cx, ey - cy)
    if not distance <= camera[DETECTION_RANGE]:
        return True
    depth_error = 0.0
    if perception[NOISY] != 0.0:  # the oracle draws both, every in-range capture
        k = noise_drawn[pair, 0]
        noise_drawn[pair, 0] += 1
        if noise[pair, k, MISS_DRAW] < perception[MISS_PROBABILITY]:
            return True
        std = perception[RANGE_NOISE] + perception[NOISE_GROWTH] * distance**2
        depth_error = std * noise[pair, k, DEPTH_DRAW]
    if perception[MISSES] != 0.0:
        hidden = 0.0
        if perception[OCCLUSION_MISS] > 0.0:
            hidden = silhouette_hidden(
                frame, blocked, values, near, far, fov, cx, cy, ctheta, ex, ey, radius
            )
        chance = miss_chance(
            distance,
            hidden,
            camera[DETECTION_RANGE],
            perception[MISS_START],
            perception[MISS_AT_RANGE],
            perception[OCCLUSION_MISS],
        )
        draw = draws[pair, drawn[pair]]
        drawn[pair] += 1
        if draw < chance:
            return True
    bearing_error = 0.0
    if perception[BEARING_NOISE] != 0.0:
        bearing_error = noise[pair, noise_drawn[pair, 1], BEARING_DRAW]
        noise_drawn[pair, 1] += 1
    out, q = detection, pair
    box_x, box_y, box_w, box_h, depth, seen_x, seen_y = image(
        camera, cx, cy, ctheta, ex, ey, distance, bearing_error, depth_error, radius
    )
    out[q, BOX_X], out[q, BOX_Y], out[q, BOX_W], out[q, BOX_H] = box_x, box_y, box_w, box_h
    out[q, DEPTH], out[q, SEEN_X], out[q, SEEN_Y] = depth, seen_x, seen_y
    detected[pair] = True
    return True


@njit(cache=True, inline="always")
def burst_step(perception: np.ndarray, state: BatchState, pair: int, dt: float) -> bool:
    """The perception model's Gilbert-Elliott chain (:func:`pegame.detectors.perception.
    burst_next`, which ``Perception._burst_step`` steps too) of detector pair row ``pair``
    over ``dt`` s, on its next 'burst' draw; True when this frame is missed."""
    k = state.noise_drawn[pair, 2]
    state.noise_drawn[pair, 2] += 1
    draw = state.noise[pair, k, BURST_DRAW]
    fraction, length = perception[BURST_FRACTION], perception[BURST_LENGTH]
    bursting = burst_next(state.bursting[pair], draw, fraction, length, dt)
    state.bursting[pair] = 1 if bursting else 0
    return bursting


@njit(cache=True, inline="always")
def false_positive(
    camera: np.ndarray,
    perception: np.ndarray,
    state: BatchState,
    pair: int,
    dt: float,
    px: float,
    py: float,
    ptheta: float,
    radius: float,
) -> None:
    """The perception model's false positive (``Perception._false_positive``) of a frame
    of detector pair row ``pair`` without a detection, ``dt`` s after its last frame, by
    the camera at (px, py, ptheta): when one arrived (a uniform below 1 - exp(-rate dt)),
    a body of the evader's ``radius`` at a uniform bearing in the field of view and a
    distance uniform over the area within the detection range, into state.capture and
    state.captured; the uniforms are the pair's 'false_positive' draws in turn."""
    k = state.noise_drawn[pair, 3]
    draws = state.noise[pair]
    arrived = draws[k // 3, FALSE_POSITIVE_DRAW + k % 3]
    if arrived >= -math.expm1(-perception[FALSE_POSITIVE_RATE] * dt):
        state.noise_drawn[pair, 3] = k + 1
        return
    u1 = draws[(k + 1) // 3, FALSE_POSITIVE_DRAW + (k + 1) % 3]
    u2 = draws[(k + 2) // 3, FALSE_POSITIVE_DRAW + (k + 2) % 3]
    state.noise_drawn[pair, 3] = k + 3
    fov, near, reach = camera[FOV], camera[NEAR], camera[DETECTION_RANGE]
    bearing = -0.5 * fov + (0.5 * fov - -0.5 * fov) * u1  # numpy's uniform(low, high)
    distance = math.sqrt(near**2 + (reach**2 - near**2) * u2)
    depth = max(near, distance * math.cos(bearing))
    x, y, w, h = body_box(camera, bearing, distance, depth, radius)
    heading = ptheta + bearing
    out, q = state.capture, pair
    out[q, BOX_X], out[q, BOX_Y], out[q, BOX_W], out[q, BOX_H], out[q, DEPTH] = x, y, w, h, depth
    out[q, SEEN_X] = px + distance * math.cos(heading)
    out[q, SEEN_Y] = py + distance * math.sin(heading)
    state.captured[q] = True


@njit(cache=True, inline="always")
def sense(world: World, rules: Rules, state: BatchState, game: int) -> None:
    """The loop's ``_sense`` for ``game``: per detector pair (pursuer i, evader j) in
    order, the detection, then ground truth in_view; then each pursuer observation's
    memory of the last detection of its target evader i mod E
    (``PursuerFeatures.remember``). When the perception pipeline runs, a pair's frame is
    captured only when one is due (into state.capture), put in flight, and the result
    delivered by then goes into state.detected and state.detection (the held one stays
    when none is); else the capture is the detection. The caller inlines it once per
    game, so that the NamedTuples' arrays are taken out once (and :func:`detect` is
    inlined once)."""
    frame, blocked, values = world.frame, world.blocked, world.sight_values
    n_p, n_e = rules.pursuers, rules.evaders
    camera, perception, radius = rules.camera, rules.perception, rules.bodies[n_p, RADIUS]
    poses, detected, detection = state.poses, state.detected, state.detection
    time = state.steps[game] * rules.control_dt
    pipeline = perception[PIPELINE] != 0.0
    period, rated = perception[PERIOD], perception[RATED] != 0.0
    near, far, fov = camera[NEAR], camera[FAR], camera[FOV]
    for i in range(n_p):
        px, py, ptheta = poses[game, i, 0], poses[game, i, 1], poses[game, i, 2]
        for j in range(n_e):
            q = (game * n_p + i) * n_e + j
            ex, ey = poses[game, n_p + j, 0], poses[game, n_p + j, 1]
            due, since = True, 0.0
            if pipeline:
                due, since = frame_due(state.pipeline, q, time, period, rated)
            if due:
                out, rows = (state.captured, state.capture) if pipeline else (detected, detection)
                centre = detect(
                    frame,
                    blocked,
                    values,
                    camera,
                    perception,
                    radius,
                    px,
                    py,
                    ptheta,
                    ex,
                    ey,
                    state.draws,
                    state.drawn,
                    state.noise,
                    state.noise_drawn,
                    out,
                    rows,
                    q,
                )
                if perception[BURST_FRACTION] > 0.0 and burst_step(perception, state, q, since):
                    state.captured[q] = False  # the frame is lost in a burst
                if perception[FALSE_POSITIVE_RATE] > 0.0 and not state.captured[q]:
                    false_positive(camera, perception, state, q, since, px, py, ptheta, radius)
            else:
                centre = point_in_view(
                    frame, blocked, values, near, far, fov, px, py, ptheta, ex, ey
                )
            if pipeline:
                latency = perception[LATENCY]
                slot_in, slot_out, _ = deliver_frame(
                    state.pipeline, q, time, period, rated, latency, due
                )
                if slot_in >= 0:
                    state.in_flight_detected[q, slot_in] = state.captured[q]
                    state.in_flight[q, slot_in, :] = state.capture[q, :]
                if slot_out >= 0:
                    detected[q] = state.in_flight_detected[q, slot_out]
                    detection[q, :] = state.in_flight[q, slot_out, :]
            state.in_view[q] = centre or silhouette_in_view(
                frame, blocked, values, near, far, fov, px, py, ptheta, ex, ey, radius, 1
            )
        target = (game * n_p + i) * n_e + i % n_e
        if detected[target]:
            seen, member = state.seen, game * n_p + i
            seen[member, 0] = time
            seen[member, 1] = detection[target, SEEN_X]
            seen[member, 2] = detection[target, SEEN_Y]
            state.has_seen[member] = True
