"""pegame-pybullet: the pursuit-evasion game in a 3D PyBullet world.

``sim=pybullet`` (:mod:`pegame_pybullet.sim`) extrudes the occupancy grid into walls,
drives a TurtleBot-like pursuer and a human-shaped evader as unicycles stopped by the
walls, and renders the pursuer's RGB-D camera with segmentation. ``detector=segmentation``
(:mod:`pegame_pybullet.segmentation`) is the reference detector on that segmentation.
Importing this package imports neither; the simulator module needs pybullet.
"""
