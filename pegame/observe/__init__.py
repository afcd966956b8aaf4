"""What a learning agent observes and how its actions become commands, below both the
strategies and the environments: a plain game that plays a learned policy imports this
package and never gymnasium or pettingzoo (:mod:`pegame.envs` holds only the Gymnasium
and PettingZoo wrappers).

- :mod:`pegame.observe.observations` - the pursuer's and evader's flat float32 observation
  vectors, shared by the envs, the batched game (:mod:`pegame.vector`) and the ``policy``
  strategies (:mod:`pegame.policies`);
- :mod:`pegame.observe.features` - the numba kernels that compute those vectors for one
  game, called by the observations and by the batched game's loop over games;
- :mod:`pegame.observe.crop` - the egocentric occupancy crop in those vectors;
- :mod:`pegame.observe.actions` - actions (v, w) scaled to [-1, 1] into velocity commands;
- :mod:`pegame.observe.settings` - :class:`~pegame.observe.settings.EnvSettings`, the
  observation options with the decision period and action clipping.

The modules are imported on use (the features and the crop compile numba kernels).
"""
