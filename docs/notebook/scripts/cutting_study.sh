#!/usr/bin/env bash
# Does the cost of cutting move the balance of the tips' loads? The needle's cut breaks the tissue's bonds
# for free, so the tips meet only the tissue's elastic push and the held loads behind the tip (the groove
# floor, the shaft) bend the needles. A gel must be fractured at the tip: --cutting-pressure-mpa p_c loads
# the tip facets in the block with p_c along their normals (docs/insertion.md), so a single bevel is pushed
# down and the bevels of a multi-bevel tip push against each other. Runs the needles 10 mm into
# data/scenes/spacing_study_10mm.json (0.2 mm particles near the path, the card at E 0.0748 MPa) for each
# pressure and prints delta and the ratios to SB (docs/notebook/paper_studies.md).
#
#   docs/notebook/scripts/cutting_study.sh [OUT] [PRESSURE_MPa...]
#       default: out/cutting, pressures 0 0.1 0.3
#   NEEDLES="SB LMB AMB HMB" docs/notebook/scripts/cutting_study.sh ...   (default NEEDLES="SB AMB"; SB must be among them)
#
# Two runs at once (one core each). A finished run (OUT/<needle>_p<p_c>/summary.json) is kept, so an
# interrupted study resumes. About 10 min a run (19 683 particles).
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/cutting}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

pressures=("$@")
[ "${#pressures[@]}" -gt 0 ] || pressures=(0 0.1 0.3)
for p in "${pressures[@]}"; do
  study_number cutting_study "'$p'" "$p" ">=0" "a pressure in MPa" 0.1
done

study_needles cutting_study

csv="$out/cutting_study.csv"
echo "needle,cutting_pressure_MPa,deflection_mm,cutting_work_mJ,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for p in "${pressures[@]}"; do
  flags=()
  [[ "$p" =~ ^0*\.?0*$ ]] || flags=(--cutting-pressure-mpa "$p")
  study_run_two_at_once cutting_study "$out" "_p$p" "${needles[*]}" --path-refinement 2 "${flags[@]}"
  for needle in "${needles[@]}"; do
    s=$(study_summary cutting_study "$out/${needle}_p$p")
    echo "$needle,$p,$(summary_number deflection_mm "$s"),$(summary_number work_mJ "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

ratio_table "$csv" "p_c (MPa)"
echo "table: $csv; runs in $out/<needle>_p<p_c>"
