"""Errors that pegame reports to the user as one clear paragraph, without a traceback."""

from typing import Any


class PegameError(Exception):
    """Base of every user-facing pegame error: bad config, bad map, bad plugin."""


class ConfigError(PegameError, ValueError):
    """A config value is missing, of the wrong type or outside its allowed range.

    Raised by :func:`require`, it keeps the ``key`` as the check wrote it, the ``value``
    and what is ``allowed``: a plugin's ``Config`` names its keys relative to its node
    (``k_v``), and the loader, which knows where the node is (``pursuer``, or a team
    member's ``team.pursuers[1]``), names the full key (:meth:`under`).
    """

    def __init__(
        self, message: str, key: str | None = None, value: Any = None, allowed: str = ""
    ) -> None:
        super().__init__(message)
        self.key, self.value, self.allowed = key, value, allowed

    def under(self, node: str, group: str | None = None) -> "ConfigError":
        """This error with its key under the config node ``node``; a key the check wrote
        under its plugin ``group`` already (``pursuer.k_v``, a plugin written before
        keys were relative) is moved from the group to the node. Errors not raised by
        :func:`require` are returned unchanged."""
        if self.key is None:
            return self
        key = self.key
        if group is not None and key.startswith(f"{group}."):
            key = key[len(group) + 1 :]
        return ConfigError(_invalid(f"{node}.{key}", self.value, self.allowed))


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


def _invalid(key: str, value: Any, allowed: str) -> str:
    return f"Invalid value for '{key}': {value!r}. Allowed: {allowed}."


def require(ok: bool, key: str, allowed: str, value: Any) -> None:
    """Raise ConfigError naming ``key``, its ``value`` and the ``allowed`` range unless ok.

    In a plugin's ``Config``, ``key`` is the field's name (relative to the plugin's node;
    the loader puts it under the node); elsewhere the full key."""
    if not ok:
        raise ConfigError(_invalid(key, value, allowed), key, value, allowed)
