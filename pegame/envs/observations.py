"""Deprecated: moved to :mod:`pegame.observe.observations` (examples/train_cem.py of 0.1.0
imported ObservationSettings from here); this re-export goes in the next minor release."""

import warnings

from pegame.observe.observations import (  # noqa: F401
    AGE_SCALE,
    EvaderFeatures,
    ObservationSettings,
    PursuerFeatures,
)

warnings.warn(
    "pegame.envs.observations is deprecated: import from pegame.observe.observations.",
    DeprecationWarning,
    stacklevel=2,
)
