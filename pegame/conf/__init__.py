"""Hydra config root of pegame, installed as the package pegame.conf."""
