# The protocol both sides of the fidelity study play (sourced by run.sh and run3d.sh):
# +experiment=paper_conditions with simultaneous moves, n = $N games per cell (default 20,
# seeds 0..N-1, common to both sides), $JOBS jobs at a time (default 1), under $OUT
# (default outputs/fidelity).
OUT=${OUT:-outputs/fidelity}
N=${N:-20}
JOBS=${JOBS:-1}
PROTOCOL="+experiment=paper_conditions game.turn_order=simultaneous game.trials=$N"
PROTOCOL="$PROTOCOL hydra.launcher.n_jobs=$JOBS"
# grid <dir> <overrides...>: the grid side's three pairings of the protocol into $OUT/<dir>
grid() {
  local dir=$1; shift
  local common="$PROTOCOL recorder=none"
  # shellcheck disable=SC2086
  python -m pegame -m $common "$@" pursuer=smart pursuer.detour=false evader=smart \
    evader.hide_margin=0 hydra.sweep.dir="$OUT/$dir/S-S" resume=true
  # shellcheck disable=SC2086
  python -m pegame -m $common "$@" pursuer=smart pursuer.detour=false evader=random \
    evader.model=action hydra.sweep.dir="$OUT/$dir/S-R" resume=true
  # shellcheck disable=SC2086
  python -m pegame -m $common "$@" pursuer=random pursuer.model=action evader=random \
    evader.model=action hydra.sweep.dir="$OUT/$dir/R-R" resume=true
}
