#!/usr/bin/env bash
# How much does delta depend on where the groove starts? The paper gives the groove's length (22 mm) and depth, not how far
# behind tip point A its front wall lies; the presets put it 3 mm behind A, just past the SB bevel's heel (2.3 mm). Between
# the heel and the groove the full rod holds the tissue above the tip up, and for a tip point above the rod's bottom
# (LMB, AMB, HMB) that load pushes down against the tissue pressed down below A. Runs the needles 10 mm into
# data/scenes/spacing_study_10mm.json (0.2 mm particles near the path, the card at E 0.0748 MPa) with --groove-start-mm
# for each start and prints delta and the ratios to SB (docs/notebook/paper_studies.md).
#
#   docs/notebook/scripts/groove_start_study.sh [OUT] [START_mm...]
#       default: out/groove_start, starts 5
#   NEEDLES="SB LMB AMB HMB" docs/notebook/scripts/groove_start_study.sh ...   (default NEEDLES="SB AMB"; SB must be among them)
#
# Two runs at once (one core each). A finished run (OUT/<needle>_g<start>/summary.json) is kept, so an interrupted study
# resumes. About 9 min a run with two at once (19 683 particles).
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/groove_start}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

starts=("$@")
[ "${#starts[@]}" -gt 0 ] || starts=(5)
for g in "${starts[@]}"; do
  study_number groove_start_study "'$g'" "$g" ">0" "a start in mm" 5
done

study_needles groove_start_study

csv="$out/groove_start_study.csv"
echo "needle,groove_start_mm,deflection_mm,groove_fill,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for g in "${starts[@]}"; do
  study_run_two_at_once groove_start_study "$out" "_g$g" "${needles[*]}" --path-refinement 2 --groove-start-mm "$g"
  for needle in "${needles[@]}"; do
    s=$(study_summary groove_start_study "$out/${needle}_g$g")
    echo "$needle,$g,$(summary_number deflection_mm "$s"),$(summary_number groove_fill "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

ratio_table "$csv" "groove start (mm)"
echo "the presets' groove, 3 mm behind A (docs/notebook/paper_results/spacing_study_10mm.csv): SB -0.212, LMB +0.045, AMB +0.355, HMB +0.647 mm"
echo "table: $csv; runs in $out/<needle>_g<start>"
