"""pegame: pursuit-evasion games with a probabilistic pursuer (see README)."""

from pegame.kernel_stamps import install as _install_kernel_stamps

# before any kernel of pegame is defined: a cached kernel is stale when a module it
# imports changed (pegame.kernel_stamps)
_install_kernel_stamps()
