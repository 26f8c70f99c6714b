#!/usr/bin/env bash
# Does the drive's speed, or reading delta at rest, change the balance of the multi-bevel tips? The paper's
# model drives at 8 m/s and reads delta at full speed; its experiment fired the needle at about 4 m/s and
# read the tip at rest. The gel's shear wave speed, sqrt(G / rho), is 3-4 m/s at the calibrated E, so the
# tissue's inertia may matter. Runs SB and AMB 10 mm into data/scenes/spacing_study_10mm.json (0.2 mm
# particles near the path) under these drives and prints delta and AMB / SB for each (docs/notebook/paper_studies.md):
#   8ms              the paper's model: 8 m/s, delta at the travel's end
#   4ms              the experiment's speed: 4 m/s (--speed-m-per-s 4)
#   8ms_hold1        8 m/s, stopped at once, held still 1 ms (--hold-ms 1): the undamped steel rings axially
#   8ms_decel_hold1  8 m/s, ramped to rest over 0.2 ms, held still 1 ms (--decel-time-ms 0.2 --hold-ms 1)
#
#   docs/notebook/scripts/dynamics_study.sh [OUT] [LAW] [E_MPa] [DRIVE...]
#       default: out/dynamics_study stiffening_elastic 0.03, every drive
#
# A finished run (OUT/<needle>_<drive>/summary.json) is kept, so an interrupted study resumes. Each run
# takes 6-20 min on one core.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/dynamics_study}"
law="${2:-stiffening_elastic}"
E="${3:-0.03}"
shift 3 || shift $#
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"

declare -A drive_flags=([8ms]="" [4ms]="--speed-m-per-s 4" [8ms_hold1]="--hold-ms 1" [8ms_decel_hold1]="--decel-time-ms 0.2 --hold-ms 1")
drives=("$@")
[ "${#drives[@]}" -gt 0 ] || drives=(8ms 4ms 8ms_hold1 8ms_decel_hold1)
for drive in "${drives[@]}"; do
  [ -n "${drive_flags[$drive]+set}" ] || { echo "dynamics_study: unknown drive '$drive' (8ms, 4ms, 8ms_hold1, 8ms_decel_hold1)" >&2; exit 2; }
done

# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

csv="$out/dynamics_study.csv"
echo "needle,drive,tissue_law,tissue_E_MPa,deflection_mm,deflection_at_travel_end_mm,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for needle in SB AMB; do
  for drive in "${drives[@]}"; do
    flags="${drive_flags[$drive]}"
    run="$out/${needle}_${drive}"
    # shellcheck disable=SC2086  # flags are words
    study_run dynamics_study "$run" "$needle" --path-refinement 2 --tissue-law "$law" --tissue-E-MPa "$E" $flags
    # delta when the travel ended: the last history row whose insertion is still short of the travel, or the first at it.
    at_travel_end=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
      { if (!done) { d = $col["deflection_mm"]; if ($col["insertion_mm"] >= 10 - 1e-9) done = 1 } }
      END { printf "%.6g", d }' "$run/history.csv")
    echo "$needle,$drive,$law,$E,$(summary_number deflection_mm "$run/summary.json"),$at_travel_end,$(summary_run_fields "$run/summary.json")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

awk -F, 'NR > 1 { d[$1, $2] = $5; e[$1, $2] = $6; s[$1, $2] = $10; if (!($2 in seen)) { seen[$2] = 1; order[++m] = $2 } }
END {
  printf "%-16s %10s %10s %9s   %s\n", "drive", "SB", "AMB", "AMB/SB", "(delta in mm at the end; at the travel'"'"'s end in brackets where a hold follows)"
  for (i = 1; i <= m; ++i) {
    k = order[i]
    printf "%-16s %+10.3f %+10.3f %9.2f", k, d["SB", k], d["AMB", k], d["SB", k] != 0 ? d["AMB", k] / d["SB", k] : 0
    if (k ~ /hold/) printf "   (%+.3f, %+.3f)", e["SB", k], e["AMB", k]
    if (s["SB", k] != "finished" || s["AMB", k] != "finished") printf "   a run stopped: see its summary.json"
    printf "\n"
  }
  printf "%-16s %10s %10s %9s\n", "experiment", "-1.14", "+0.24", "-0.21 (at 30 mm)"
}' "$csv"
echo "table: $csv; runs in $out/<needle>_<drive>"
