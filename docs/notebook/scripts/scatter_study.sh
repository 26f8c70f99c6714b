#!/usr/bin/env bash
# How far does delta scatter from run to run? The particle lattice starts at the block's entry face, so moving that face a
# fraction of the spacing ahead of tip point A's start (--tissue-entry-x-mm) meets the tip with a lattice shifted against
# its path; nothing else changes but that much less depth at the end. Runs the needles 30 mm with `needle paper` (the
# default model, E from the SB calibration) for each shift and prints delta beside the unshifted main report's
# (docs/notebook/paper_results/results.json), and the spread (docs/notebook/paper_studies.md). Each shift's runs also get a report, OUT/entry<shift>,
# whose results.json is a replica for the main report: `needle paper ... --replica "lattice +<shift> mm=OUT/entry<shift>/results.json"`.
#
#   docs/notebook/scripts/scatter_study.sh [OUT] [SHIFT_mm...]
#       default: out/scatter, shift 0.1 (half a spacing of the 0.2 mm particles near the path)
#   NEEDLES="SB LMB AMB HMB" docs/notebook/scripts/scatter_study.sh ...   (default NEEDLES="SB LMB AMB")
#   CALIBRATION=calib/calibration.json docs/notebook/scripts/scatter_study.sh ...   (default data/paper/calibration_sb.json)
#
# Two runs at once (one thread each), each a one-needle report OUT/entry<shift>_<needle>. A finished run
# (OUT/entry<shift>_<needle>/runs/<needle>/summary.json) is kept, so an interrupted study resumes. About 76 min a run with
# four at once on the two cores; 21 min alone on two idle threads.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/scatter}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

calibration="${CALIBRATION:-data/paper/calibration_sb.json}"
[ -f "$calibration" ] || { echo "scatter_study: no calibration file '$calibration'" >&2; exit 2; }
shifts=("$@")
[ "${#shifts[@]}" -gt 0 ] || shifts=(0.1)
for s in "${shifts[@]}"; do
  study_number scatter_study "'$s'" "$s" ">0" "a shift in mm" 0.1
done
read -r -a needles <<< "${NEEDLES:-SB LMB AMB}"
for needle in "${needles[@]}"; do
  [[ " SB LMB AMB HMB " == *" $needle "* ]] || { echo "scatter_study: NEEDLES: '$needle' is not one of SB, LMB, AMB, HMB" >&2; exit 2; }
done

# scatter_run NEEDLE SHIFT: one needle's 30 mm run with the entry face SHIFT mm ahead, unless it is there already.
scatter_run() {
  local report="$out/entry$2_$1"
  if [ ! -f "$report/runs/$1/summary.json" ]; then
    ./build/apps/needle paper --needles "$1" --calibration "$calibration" --tissue-entry-x-mm "$2" --threads 1 --no-tips --quiet \
      --out "$report" || true
  fi
  [ -f "$report/runs/$1/summary.json" ] || { echo "scatter_study: no summary in $report/runs/$1" >&2; exit 1; }
}

cases=()
for s in "${shifts[@]}"; do
  for needle in "${needles[@]}"; do cases+=("$needle $s"); done
done
for ((i = 0; i < ${#cases[@]}; i += 2)); do
  { scatter_run ${cases[i]} & }
  if [ $((i + 1)) -lt ${#cases[@]} ]; then { scatter_run ${cases[i + 1]} & }; fi
  wait
done

csv="$out/scatter_study.csv"
echo "needle,entry_x_mm,deflection_mm,groove_fill,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for s in "${shifts[@]}"; do
  for needle in "${needles[@]}"; do
    f=$(study_summary scatter_study "$out/entry${s}_$needle/runs/$needle")
    echo "$needle,$s,$(summary_number deflection_mm "$f"),$(summary_number groove_fill "$f"),$(summary_run_fields "$f")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

# One report per shift over its needles' runs (linked, not copied): its results.json is the main report's replica.
list=$(IFS=,; echo "${needles[*]}")
for s in "${shifts[@]}"; do
  mkdir -p "$out/entry$s/runs"
  for needle in "${needles[@]}"; do ln -sfn "../../entry${s}_$needle/runs/$needle" "$out/entry$s/runs/$needle"; done
  ./build/apps/needle paper --report-only --needles "$list" --calibration "$calibration" --tissue-entry-x-mm "$s" --no-tips --quiet \
    --out "$out/entry$s"
done

# The unshifted deltas: each needle's "deflection_mm" in the main report's results.json (one needle object per line block).
base="docs/notebook/paper_results/results.json"
awk -F, -v base="$base" '
  BEGIN { while ((getline line < base) > 0) {
            if (match(line, /"(SB|LMB|AMB|HMB)": *\{/)) { n = substr(line, RSTART + 1); sub(/".*/, "", n) }
            if (n != "" && match(line, /"deflection_mm": *[-0-9.eE+]+/)) { v = substr(line, RSTART, RLENGTH); sub(/.*: */, "", v); d0[n] = v + 0; n = "" } } }
  NR > 1 { v = $3 + 0; d[$1] = d[$1] " " sprintf("%+.3f", v) " (" $2 ")"
           if (!($1 in known)) { known[$1] = 1; order[++k] = $1; lo[$1] = v; hi[$1] = v }
           if (v < lo[$1]) lo[$1] = v
           if (v > hi[$1]) hi[$1] = v
           if ($8 != "finished") bad[$1] = 1 }
  END {
    printf "needle  unshifted  shifted (entry mm)            spread (max - min, all)\n"
    for (j = 1; j <= k; ++j) {
      m = order[j]; a = lo[m]; b = hi[m]
      if (m in d0) { if (d0[m] < a) a = d0[m]; if (d0[m] > b) b = d0[m] }
      printf "%-6s  %9s  %-28s  %.3f%s\n", m, (m in d0) ? sprintf("%+.3f", d0[m]) : "-", d[m], b - a, (m in bad) ? "   a run stopped: see its summary.json" : ""
    }
    printf "experiment at 30 mm: SB -1.14, LMB +0.15, AMB +0.24, HMB +1.71; the target for SB, LMB and AMB: within 0.1 mm\n"
  }' "$csv"
echo "table: $csv; runs in $out/entry<shift>_<needle>; a replica report per shift in $out/entry<shift> (its results.json for --replica)"
