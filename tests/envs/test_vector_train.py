"""examples/train_vector_cem.py trains what examples/train_cem.py trains, and its pursuer
plays in ordinary games (pursuer=policy)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

from pegame.config import compose
from pegame.game import Game
from pegame.policies import LinearPolicy

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def run_example(name: str, monkeypatch, *args: str) -> None:
    """Run examples/<name>.py's main() with ``args``, its folder on sys.path as when the
    script is run (train_vector_cem.py imports train_cem.py)."""
    monkeypatch.syspath_prepend(str(EXAMPLES))
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setattr(sys, "argv", [name, *args])
    module.main()


def test_batched_cem_trains_the_single_env_trainers_policy(tmp_path, monkeypatch):
    args = ["--generations", "2", "--population", "3", "--episodes", "1", "--t-max", "1.5"]
    run_example("train_cem", monkeypatch, *args, "--out", str(tmp_path / "single.npz"))
    run_example("train_vector_cem", monkeypatch, *args, "--out", str(tmp_path / "batched.npz"))
    single = LinearPolicy.load(tmp_path / "single.npz")
    batched = LinearPolicy.load(tmp_path / "batched.npz")
    assert np.array_equal(single.weights, batched.weights)
    assert np.array_equal(single.bias, batched.bias)
    assert np.abs(batched.weights).max() > 0  # it moved away from the zero start
    cfg = compose(
        [
            "env=enclosed",
            "game.t_max=2",
            "recorder=none",
            "pursuer=policy",
            f"pursuer.path={tmp_path / 'batched.npz'}",
        ]
    )
    result = Game(cfg).play(str(tmp_path)).result
    assert 0.0 <= result["tracking_rate"] <= 1.0
