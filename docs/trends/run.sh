#!/usr/bin/env bash
# The trends study (README.md): Table 1's three pairings under paper_conditions and under
# each named reading (pegame/conf/experiment/reading_*.yaml, and the random agents' model),
# n = $N per cell on seeds 0..N-1, then the side-by-side tables, then the tick-by-tick
# measures of the servo and the random agents (servo.md). Writes sweeps into $OUT.
#   OUT=outputs/trends N=10 bash docs/trends/run.sh
set -euo pipefail
OUT=${OUT:-outputs/trends}
N=${N:-10}
SMART_P="pursuer=smart pursuer.detour=false"
SMART_E="evader=smart evader.hide_margin=0"
RANDOM_P="pursuer=random pursuer.model=action"
RANDOM_E="evader=random evader.model=action"
run() {  # run <reading> <preset> <pairing> <overrides...>: one pairing's env x ratio sweep
  local reading=$1 preset=$2 pairing=$3; shift 3
  nice python -m pegame -m +experiment="$preset" game.trials="$N" hydra.launcher.n_jobs=1 \
    "$@" hydra.sweep.dir="$OUT/$reading/$pairing"
}
for reading in paper_conditions held_commands; do
  preset=$([ $reading = paper_conditions ] && echo paper_conditions || echo reading_$reading)
  run $reading "$preset" R-R $RANDOM_P $RANDOM_E
  run $reading "$preset" S-R $SMART_P $RANDOM_E
  run $reading "$preset" S-S $SMART_P $SMART_E
done
# pursuer.track exists for the smart pursuer only: its R-R is paper_conditions' game
run goal_tracking reading_goal_tracking S-R $SMART_P $RANDOM_E
run goal_tracking reading_goal_tracking S-S $SMART_P $SMART_E
# The random agents' other reading, their default model (waypoint: move_base to random
# goals), a strategy setting and so on the command line: R-R and S-R (S-S has none)
run random_waypoints paper_conditions R-R pursuer=random evader=random
run random_waypoints paper_conditions S-R $SMART_P evader=random
# A probe, not a reading: does the scan after a loss make the fast pursuer's losses long?
# (the servo's scan rate, 1 rad/s, at the body's 1.8 rad/s; README, "Speed")
run probe_scan_rate paper_conditions S-R $SMART_P $RANDOM_E pursuer.scan_rate=1.8
python docs/trends/readings.py "$OUT" --out docs/trends
python docs/trends/servo.py --seeds "$N" --readings paper_conditions,held_commands,goal_tracking \
  --out docs/trends
python docs/trends/trajectories.py --out docs/trends
