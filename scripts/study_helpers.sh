# Sourced by the 10 mm study scripts (spacing, dynamics, domain): run one case, read fields of its summary.json without a JSON tool.

# study_run STUDY RUN NEEDLE [FLAG...]: NEEDLE 10 mm into data/scenes/spacing_study_10mm.json with the FLAGs, into the folder RUN,
# unless RUN already holds a run (so an interrupted study resumes). A run the solver stopped is kept and reported with its status;
# no summary at all ends the study.
study_run() {
  local study="$1" run="$2" needle="$3"
  shift 3
  if [ ! -f "$run/summary.json" ]; then
    ./build/apps/needle run --scene data/scenes/spacing_study_10mm.json --preset "$needle" "$@" --out "$run" --overwrite || true
  fi
  [ -f "$run/summary.json" ] || { echo "$study: no summary in $run" >&2; exit 1; }
}

# summary_number KEY FILE: the first numeric value of "KEY":
summary_number() {
  grep -o "\"$1\": *[-0-9.eE+]*" "$2" | head -1 | sed 's/.*: *//'
}
# summary_status FILE: the run's status (finished, stopped)
summary_status() {
  grep -o '"status": *"[a-z]*"' "$1" | head -1 | sed 's/.*: *"//; s/"//'
}
# summary_run_fields FILE: the columns every study table ends with: coupling_steps,max_energy_balance_error,runtime_s,status
summary_run_fields() {
  echo "$(summary_number steps "$1"),$(summary_number max_energy_balance_error "$1"),$(summary_number runtime_s "$1"),$(summary_status "$1")"
}
