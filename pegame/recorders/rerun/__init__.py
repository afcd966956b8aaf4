"""The Rerun recorder (``recorder=rerun``): one Rerun recording per game.

``python -m pegame.replay <run dir>`` opens a run's recordings. The modules, one idea each:

=================== ===================================================================
:mod:`.recorder`    :class:`RerunRecorder`: start, log, finish or abort, the sends
:mod:`.scene`       every entity path: statics, looks and one ``log_<family>()`` each
:mod:`.columns`     the buffers between sends and their encoding as Rerun columns
:mod:`.blueprint`   the viewer's layout, with the entities' looks, written once per
                    output directory as ``pegame.rbl``
:mod:`.properties`  the recording's id, name and properties (config, result, failure)
=================== ===================================================================

Files: ``<out_dir>/<game_id>.rrd.partial`` while the game runs, renamed to
``<game_id>.rrd`` when it finishes or ``<game_id>.failed.rrd`` when it raises (see
:mod:`pegame.recorders.files`); ``<out_dir>/pegame.rbl``, the layout of all of them.

Timelines: ``step`` (control tick index, sequence) and ``sim_time`` (simulation time,
duration in s). Entity paths below; ``world`` is the map frame in metres, right-handed
with z up (overlays sit a few cm above the map so that nothing z-fights), shown in a 3D
view that looks straight down on the map, as RViz does:

========================== =========================================================
world/map                  GridMap of the occupancy grid: cell size = resolution,
                           lower-left corner at the map origin (static)
world/pursuer/pose         Points3D, a ball of the body radius          every tick
world/pursuer/heading      Arrows3D                                     every tick
world/pursuer/trajectory   LineStrips3D, the segment from the previous trajectory point
                           to the position, every ``trail_every`` ticks and at the
                           last one; the map view shows every segment up to the time
                           cursor (a visible time range on this entity)
world/pursuer/fov          LineStrips3D, ``fov_wedge`` at the zero pose (static),
                           placed by a Transform3D                      every tick
world/pursuer/visible      LineStrips3D, outline of the visibility region every tick
                           (:mod:`pegame.visibility.outlines`)
world/pursuer/path, goal   the current plan's path and goal            new plans
world/evader/...           pose, heading, trajectory, path and goal (the chosen
                           escape point), as the pursuer's
world/evader/candidates    Points3D, ``plan.info["candidates"]``        new plans
world/detection            Points3D, the detection's map position       every tick
world/belief/mean          Points3D, the estimate                       every tick
world/belief/particles     Points3D coloured by weight, a strided subsample,
                           every ``particles_every`` ticks
camera/frame               LineStrips2D, the image border (static)
camera/image               JPEG of ``frame.rgb`` every ``image_every`` ticks, if any
camera/detection           Boxes2D, the detection's bounding box (px)   every tick,
                           when the simulator renders images
plots/tracking/detected    Scalars: detected (0/1)                      every tick
plots/tracking/rate        Scalars: running tracking rate               every tick
plots/distance/true        Scalars: pursuer-evader distance (m)         every tick
plots/distance/estimate_error  Scalars: |belief.mean - true evader| (m), when estimated
plots/n_eff                Scalars: the estimator's N_eff, when it gives one
events                     TextLog: loss, reacquisition, pursuer mode, game over, or
                           (ERROR) the failure of the game
losses                     TextLog (WARN): each loss of track, its pair and its cause
                           (:mod:`pegame.losses`); the events' loss line names the
                           cause too                                    each loss
config                     TextDocument: the run config as YAML (static)
========================== =========================================================

A tick with nothing to show (no detection, no estimate) gets an empty row, which clears
the entity in the viewer. Recording properties: the recording name, ``config`` and, at
the end, ``result`` or ``failure`` (see :mod:`.properties`). The default blueprint shows
the map view large and, beside it, the camera (when the simulator renders images), the
plots, the events, the losses and the config.
"""

from pegame.recorders.rerun.properties import recording_id, recording_name
from pegame.recorders.rerun.recorder import RerunRecorder

__all__ = ["RerunRecorder", "recording_id", "recording_name"]
