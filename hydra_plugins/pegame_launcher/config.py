"""The launcher's config node, ``hydra/launcher=pegame``."""

from dataclasses import dataclass

from hydra.core.config_store import ConfigStore


@dataclass
class PegameLauncherConf:
    """``n_jobs``: how many jobs run at once, each in its own worker process; -1 is one
    per CPU core, -2 one fewer, and so on (joblib's convention)."""

    _target_: str = "hydra_plugins.pegame_launcher.launcher.PegameLauncher"
    n_jobs: int = -1


ConfigStore.instance().store(
    group="hydra/launcher", name="pegame", node=PegameLauncherConf, provider="pegame"
)
