"""Recorders: what a game leaves behind besides its result.

=============================== ==========================================================
:mod:`pegame.recorders.none`    ``recorder=none``: :class:`NullRecorder` records nothing
:mod:`pegame.recorders.rerun`   ``recorder=rerun``: :class:`RerunRecorder`, one Rerun
                                recording per game (imports rerun-sdk)
:mod:`pegame.recorders.files`   recording file names and their statuses (complete,
                                failed, partial), shared with :mod:`pegame.replay`
=============================== ==========================================================

Recorders register as entry points of group ``pegame.recorders``; importing this package
imports none of them.
"""
