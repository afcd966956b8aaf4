#!/usr/bin/env bash
# The round-robin (README, "Stronger strategies"): every pursuer (random, smart,
# anticipating, the learned policy) against every evader (random, smart, elusive) on the
# three maps at the three speed ratios, N games per cell (seeds 0..N-1), under the
# defaults and under +experiment=paper_conditions.
# Writes the games into $OUT (default outputs/round_robin) and the tables, heat maps and
# paired tests into docs/round_robin/ (docs/round_robin/analyse.py).
#
# Each strategy runs with the settings its study gives it: under paper_conditions the
# paper's agents take the paper's bare settings (docs/paper_conditions/run.sh) and the
# anticipating pursuer the smart pursuer's detour=false; the elusive evader and the
# policy pursuer have no paper settings. Pairings run in the order of the issue's goals
# (the goal pairings first), so an interrupted run leaves the goals answered; a rerun
# with RESUME=true skips the games already stored.
set -euo pipefail
OUT=${OUT:-outputs/round_robin}
N=${N:-40}
JOBS=${JOBS:-2}
RESUME=${RESUME:-false}
pursuer() {  # pursuer <name> <conditions>: its overrides
  case $1 in
    random) [ "$2" = paper_conditions ] && echo "pursuer=random pursuer.model=action" || echo "pursuer=random" ;;
    smart) [ "$2" = paper_conditions ] && echo "pursuer=smart pursuer.detour=false" || echo "pursuer=smart" ;;
    anticipating) [ "$2" = paper_conditions ] && echo "pursuer=anticipating pursuer.detour=false" || echo "pursuer=anticipating" ;;
    policy) echo "pursuer=policy pursuer.path=examples/cem_pursuer.npz" ;;
  esac
}
evader() {  # evader <name> <conditions>: its overrides
  case $1 in
    random) [ "$2" = paper_conditions ] && echo "evader=random evader.model=action" || echo "evader=random" ;;
    smart) [ "$2" = paper_conditions ] && echo "evader=smart evader.hide_margin=0" || echo "evader=smart" ;;
    elusive) echo "evader=elusive" ;;
  esac
}
run() {  # run <conditions> <pursuer> <evader>: one pairing's map x speed-ratio sweep
  local experiment=""
  [ "$1" = paper_conditions ] && experiment=+experiment=paper_conditions
  python -m pegame -m $experiment env=hall,enclosed,brick game.speed_ratio=0.5,1,2 \
    game.trials="$N" resume="$RESUME" recorder=none $(pursuer "$2" "$1") $(evader "$3" "$1") \
    hydra.launcher.n_jobs="$JOBS" hydra.sweep.dir="$OUT/$1/$2-$3"
}
for pairing in anticipating:smart smart:smart smart:elusive anticipating:random smart:random \
    anticipating:elusive random:random random:smart random:elusive policy:random policy:smart \
    policy:elusive; do
  for conditions in paper_conditions default; do
    run "$conditions" "${pairing%%:*}" "${pairing##*:}"
  done
done
python docs/round_robin/analyse.py "$OUT" --out docs/round_robin
