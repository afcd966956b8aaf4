#!/usr/bin/env bash
# The paper-conditions study (README, "The paper's conditions, measured"): Table 1 under
# +experiment=paper_conditions, and the factor table. Writes into $OUT (default
# outputs/paper_conditions) and the report into docs/paper_conditions/.
set -euo pipefail
OUT=${OUT:-outputs/paper_conditions}
N=${N:-40}
SMART_P="pursuer=smart pursuer.detour=false"
SMART_E="evader=smart evader.hide_margin=0"
RANDOM_P="pursuer=random pursuer.model=action"
RANDOM_E="evader=random evader.model=action"
run() {  # run <dir> <overrides...>: one pairing's env x ratio sweep
  local dir=$1; shift
  python -m pegame -m +experiment=paper_conditions game.trials="$N" "$@" hydra.sweep.dir="$OUT/$dir"
}
run table1/R-R $RANDOM_P $RANDOM_E
run table1/S-R $SMART_P $RANDOM_E
run table1/S-S $SMART_P $SMART_E
python -m pegame.report "$OUT"/table1/R-R "$OUT"/table1/S-R "$OUT"/table1/S-S --out docs/paper_conditions/table1
