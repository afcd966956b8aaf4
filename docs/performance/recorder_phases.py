"""Where a Rerun recording's instructions go, phase by phase, counted by callgrind.

    python docs/performance/recorder_phases.py [--seed 0] [--env enclosed] [OVERRIDE ...]

Plays one 90 s S-S game with ``recorder=rerun`` (and the overrides, such as
``recorder.max_particles=50``), keeps what the recorder was given (its config, context,
start properties, every tick and the result) in a temporary pickle, then replays them
through a fresh :class:`~pegame.recorders.rerun.RerunRecorder` in a worker under
``valgrind --tool=callgrind --instr-atstart=no``: a first replay warms up (imports, the
outline kernel), the second is counted with a ``callgrind_control --dump`` after each
phase: ``start`` (stream, statics, config), ``ticks`` (buffering every tick, and the
blueprint at the first), ``flush`` (building and sending the columns), ``close``
(rerun-sdk encoding the .rrd, and writing it) and ``rest`` (the result property). The
report gives each phase's instructions (Ir) and share. Counts are the same however loaded
the machine is (``ab_instructions.py`` explains why), but numba's kernels and numpy run
other code paths under valgrind than natively, so compare recordings with recordings,
not with a game. A run takes a few minutes.
"""

from __future__ import annotations

import argparse
import os
import pickle
import re
import subprocess
import sys
import tempfile
from pathlib import Path

PHASES = ("start", "ticks", "flush", "close", "rest")


def capture(overrides: list[str], path: Path) -> None:
    """Play the game and pickle (config, context, properties, ticks, result) to ``path``."""
    from pegame.config import compose
    from pegame.game import Game
    from pegame.recorders.rerun.recorder import RerunRecorder

    seen: dict = {"ticks": []}
    start, log, finish = RerunRecorder.start, RerunRecorder.log, RerunRecorder.finish

    def on_start(self, out_dir, game_id, properties):
        seen.update(recorder=self, properties=properties)
        start(self, out_dir, game_id, properties)

    def on_log(self, tick):
        seen["ticks"].append(tick)
        log(self, tick)

    def on_finish(self, result):
        seen["result"] = result
        finish(self, result)

    RerunRecorder.start, RerunRecorder.log, RerunRecorder.finish = on_start, on_log, on_finish
    with tempfile.TemporaryDirectory() as out_dir:
        Game(compose(["pursuer=smart", "evader=smart", "recorder=rerun", *overrides])).play(out_dir)
    recorder = seen["recorder"]
    given = (recorder.config, recorder.context, seen["properties"], seen["ticks"], seen["result"])
    path.write_bytes(pickle.dumps(given))


def worker(path: Path) -> None:
    """Replay the pickled recording twice, dumping callgrind's counts after each phase of
    the second (module docstring)."""
    import numpy as np

    from pegame.recorders.rerun.recorder import RerunRecorder

    config, context, properties, ticks, result = pickle.loads(path.read_bytes())

    def control(*args: str) -> None:
        command = ["callgrind_control", *args, str(os.getpid())]
        subprocess.run(command, check=True, capture_output=True)

    def replay(out_dir: str, counted: bool) -> None:
        recorder = RerunRecorder(config, context, np.random.default_rng(0))
        mark = control if counted else (lambda *args: None)
        flush, close = recorder._flush, recorder._close
        recorder._flush = lambda final=False: (flush(final), mark("--dump=flush"))
        recorder._close = lambda status: (close(status), mark("--dump=close"))
        mark("-i", "on")
        recorder.start(out_dir, "game", properties)
        mark("--dump=start")
        for tick in ticks:
            recorder.log(tick)
        mark("--dump=ticks")
        recorder.finish(result)
        mark("--dump=rest")
        mark("-i", "off")

    with tempfile.TemporaryDirectory() as out_dir:
        replay(out_dir, counted=False)
        replay(out_dir, counted=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--env", default="enclosed")
    parser.add_argument("overrides", nargs="*", help="more Hydra overrides of the game")
    parser.add_argument("--worker", metavar="PICKLE", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(Path(args.worker))
        return
    with tempfile.TemporaryDirectory() as scratch:
        given = Path(scratch) / "recording.pickle"
        capture([f"env={args.env}", f"game.seed={args.seed}", *args.overrides], given)
        out = os.path.join(scratch, "callgrind.out")
        python = sys.executable  # the interpreter itself, not a launcher such as pyenv's shim
        subprocess.run(
            [
                "valgrind",
                "--tool=callgrind",
                "--instr-atstart=no",
                f"--callgrind-out-file={out}",
                f"--log-file={os.path.join(scratch, 'valgrind.log')}",
                python,
                os.path.abspath(__file__),
                "--worker",
                str(given),
            ],
            check=True,
        )
        counts = {}
        for dump in Path(scratch).glob("callgrind.out.*"):
            text = dump.read_text(encoding="utf-8", errors="replace")
            phase = re.search(r"^desc: Trigger: dump (\w+)", text, re.MULTILINE)
            total = re.search(r"^summary:\s+(\d+)", text, re.MULTILINE)
            if phase and total:
                counts[phase.group(1)] = int(total.group(1))
    everything = sum(counts.values())
    print(f"recording of a {args.env} S-S game, seed {args.seed} {' '.join(args.overrides)}")
    for phase in PHASES:
        ir = counts.get(phase, 0)
        print(f"{phase:6s} {ir / 1e6:8.1f} M instructions {100 * ir / everything:5.1f}%")
    print(f"total  {everything / 1e6:8.1f} M")


if __name__ == "__main__":
    main()
