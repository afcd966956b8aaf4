"""One strategy for either role: a behaviour written once, played as the pursuer or as the
evader.

A role-generic behaviour (the random agents of :mod:`pegame.wander`, the learned policies
of :mod:`pegame.policies`) is a mixin class with a ``description`` and the strategy
methods, reading its role's body as ``getattr(context, self.role)``; its parameters are a
dataclass with a ``check(role)`` method. :func:`for_role` makes the plugin class of one
role from them: a subclass of the behaviour and of the role's interface
(:class:`pegame.api.Pursuer` or :class:`pegame.api.Evader`) whose ``Config`` is the role's
body config extended by the parameters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

from pegame.api import PLUGIN_KINDS, Evader, Pursuer


class Options(Protocol):
    """A behaviour's parameters: a dataclass that checks its values for ``role``, naming
    its keys relative to the node (``path``, not ``pursuer.path``)."""

    def check(self, role: str) -> None: ...


def role_of(interface: type[Pursuer] | type[Evader]) -> str:
    """The config group of ``interface``: ``'pursuer'`` or ``'evader'``."""
    return next(kind for kind, spec in PLUGIN_KINDS.items() if spec.interface is interface)


def for_role(
    behaviour: type,
    options: type[Options],
    interface: type[Pursuer] | type[Evader],
    module: str,
) -> type[Pursuer] | type[Evader]:
    """The plugin class playing ``behaviour`` as ``interface``'s role, named after both
    (``RandomStrategy`` and ``Pursuer`` give ``RandomPursuer``) and defined in ``module``
    (the module that binds it to that name, so that it pickles). Its ``Config`` holds the
    role's body fields and those of ``options``, checked by both."""
    role = role_of(interface)
    body = interface.Config

    def __post_init__(self: Any) -> None:
        body.__post_init__(self)
        self.check(role)

    name = behaviour.__name__.removesuffix("Strategy") + interface.__name__
    config: type = dataclass(
        type(
            "Config",
            (options, body),
            {
                "__post_init__": __post_init__,
                "__module__": module,
                "__qualname__": f"{name}.Config",
            },
        )
    )
    namespace = {"Config": config, "role": role, "__module__": module, "__doc__": behaviour.__doc__}
    return type(name, (behaviour, interface), namespace)
