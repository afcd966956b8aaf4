"""Errors that pegame reports to the user as one clear paragraph, without a traceback."""

from typing import Any


class PegameError(Exception):
    """Base of every user-facing pegame error: bad config, bad map, bad plugin."""


class ConfigError(PegameError, ValueError):
    """A config value is missing, of the wrong type or outside its allowed range."""


class MapError(PegameError, ValueError):
    """A map file is missing, malformed or inconsistent; the message names the file."""


class SpawnError(PegameError, RuntimeError):
    """No valid pair of start poses exists on the map for the configured agents."""


class ResultsWriteError(PegameError, OSError):
    """A result file could not be written (a full disk, a read-only directory)."""


class JobDirectoryError(PegameError, RuntimeError):
    """A job directory belongs to another job: it holds another config's games, or
    another process writes to it. Nothing is written to it."""


class PluginChoiceError(PegameError, LookupError):
    """A plugin group on the command line names an option that does not exist."""


def require(ok: bool, key: str, allowed: str, value: Any) -> None:
    """Raise ConfigError naming ``key``, its ``value`` and the ``allowed`` range unless ok."""
    if not ok:
        raise ConfigError(f"Invalid value for '{key}': {value!r}. Allowed: {allowed}.")
