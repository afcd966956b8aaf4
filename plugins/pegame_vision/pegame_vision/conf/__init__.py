"""Config files of pegame-vision, found by pegame through the pegame.configs entry point."""
