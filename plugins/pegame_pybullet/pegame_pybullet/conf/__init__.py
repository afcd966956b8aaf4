"""Config files of pegame-pybullet, found by pegame through the pegame.configs entry point."""
