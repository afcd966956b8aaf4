"""pegame-vision: ``detector=vision``, the pursuer's evader detector on RGB-D images.

A colour model of the evader's clothing finds it (:mod:`pegame_vision.colour`), pyramidal
Lucas-Kanade optical flow tracks its box between detections (:mod:`pegame_vision.tracker`),
and the depth image places it on the map (:mod:`pegame_vision.detector`), as the paper's
pursuer does with OpenPose and Lucas-Kanade (Sec. "Object tracking from static camera").
:func:`pegame_vision.evaluate.evaluate` measures it against ``detector=segmentation``.
"""
