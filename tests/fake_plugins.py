"""Deliberately broken plugins for the registry's error tests."""

from pegame.api import Pursuer


class HalfPursuer(Pursuer):
    """Forgets to implement decide and control."""

    def reset(self, pose):
        pass


class NotAPlugin:
    """Implements nothing of the interface."""
