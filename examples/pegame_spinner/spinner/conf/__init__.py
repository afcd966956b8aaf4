"""Config files of the spinner pursuer, found by pegame through the pegame.configs entry point."""
