# Sourced by the 10 mm study scripts (scripts/*_study.sh): run cases, read fields of their summary.json without a JSON tool, print ratio tables.

# study_run STUDY RUN NEEDLE [FLAG...]: NEEDLE (a preset name, or a recipe file *.json) 10 mm into
# data/scenes/spacing_study_10mm.json with the FLAGs, into the folder RUN, unless RUN already holds a run (so an interrupted study
# resumes). A run the solver stopped is kept and reported with its status; no summary at all ends the study.
study_run() {
  local study="$1" run="$2" needle="$3"
  shift 3
  local -a source=(--preset "$needle")
  [[ "$needle" == *.json ]] && source=(--recipe "$needle")
  if [ ! -f "$run/summary.json" ]; then
    ./build/apps/needle run --scene data/scenes/spacing_study_10mm.json "${source[@]}" "$@" --out "$run" --overwrite || true
  fi
  [ -f "$run/summary.json" ] || { echo "$study: no summary in $run" >&2; exit 1; }
}

# study_run_two_at_once STUDY OUT CASE "NEEDLE..." [FLAG...]: study_run for each NEEDLE into OUT/<NEEDLE>CASE, two at once
# (one core each).
study_run_two_at_once() {
  local study="$1" out="$2" case="$3" i
  local -a names
  read -r -a names <<< "$4"
  shift 4
  for ((i = 0; i < ${#names[@]}; i += 2)); do
    { study_run "$study" "$out/${names[i]}$case" "${names[i]}" "$@" & }
    if [ $((i + 1)) -lt ${#names[@]} ]; then
      { study_run "$study" "$out/${names[i + 1]}$case" "${names[i + 1]}" "$@" & }
    fi
    wait
  done
}

# study_number STUDY SHOWN VALUE SIGN WHAT EXAMPLE: VALUE must be a plain decimal number, > 0 (SIGN ">0") or >= 0 (SIGN ">=0");
# otherwise one line, "STUDY: SHOWN is not WHAT (a number SIGN, e.g. EXAMPLE)", and exit 2. SHOWN is how the user gave it,
# e.g. "'0.02'" for an argument or "K='x'" for a variable.
study_number() {
  local study="$1" shown="$2" value="$3" sign="$4" what="$5" example="$6" ok=1
  [[ "$value" =~ ^[0-9]*\.?[0-9]+$ ]] || ok=0
  [ "$sign" != ">0" ] || [[ ! "$value" =~ ^0*\.?0*$ ]] || ok=0
  [ "$ok" = 1 ] || { echo "$study: $shown is not $what (a number ${sign%0} 0, e.g. $example)" >&2; exit 2; }
}

# study_needles STUDY: the NEEDLES the study runs (default "SB AMB") into the array `needles`; SB must be among them, since
# the ratios are to SB (one line and exit 2 otherwise).
study_needles() {
  read -r -a needles <<< "${NEEDLES:-SB AMB}"
  [[ " ${needles[*]} " == *" SB "* ]] || { echo "$1: NEEDLES must include SB (the ratios are to SB)" >&2; exit 2; }
}

# study_summary STUDY RUN: RUN's summary.json, or a message and failure when there is none.
study_summary() {
  [ -f "$2/summary.json" ] || { echo "$1: no summary in $2" >&2; return 1; }
  echo "$2/summary.json"
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

# ratio_table CSV LABEL: delta of each needle for each case, and the ratios to SB, from a study table whose columns are
# needle,case,deflection_mm,... with the run's status in column 8 (the cutting and crack studies).
ratio_table() {
  awk -F, -v label="$2" 'NR > 1 { d[$1, $2] = $3; s[$1, $2] = $8; if (!($2 in seen)) { seen[$2] = 1; order[++m] = $2 } if (!($1 in known)) { known[$1] = 1; needle[++k] = $1 } }
  END {
    w = length(label); for (i = 1; i <= m; ++i) if (length(order[i]) > w) w = length(order[i])  # the case column fits its longest name
    printf "%-" w "s", label
    for (j = 1; j <= k; ++j) printf " %9s", needle[j]
    for (j = 1; j <= k; ++j) if (needle[j] != "SB") printf " %9s", needle[j] "/SB"
    printf "   (delta in mm at 10 mm)\n"
    for (i = 1; i <= m; ++i) {
      p = order[i]; bad = 0
      printf "%-" w "s", p
      for (j = 1; j <= k; ++j) {
        if (!((needle[j], p) in d)) { printf " %9s", "-"; continue }  # not run for this case
        printf " %+9.3f", d[needle[j], p]; if (s[needle[j], p] != "finished") bad = 1
      }
      for (j = 1; j <= k; ++j) if (needle[j] != "SB") {
        if (((needle[j], p) in d) && d["SB", p] != 0) printf " %9.2f", d[needle[j], p] / d["SB", p]; else printf " %9s", "-"
      }
      if (bad) printf "   a run stopped: see its summary.json"
      printf "\n"
    }
    printf "experiment at 30 mm: SB -1.14, LMB +0.15, AMB +0.24, HMB +1.71 (LMB/SB -0.13, AMB/SB -0.21, HMB/SB -1.50)\n"
  }' "$1"
}
