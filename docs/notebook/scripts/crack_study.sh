#!/usr/bin/env bash
# Does a crack past the rod's outline move the balance of the tips' loads? The needle's cut separates the gel only along
# the rod's own surface, so for a tip point above the rod's bottom (LMB, AMB, HMB) the tissue below it stays bonded to the
# tissue beside the rod and presses the whole shaft up. --crack-reach-mm R cuts the bonds across fins that leave tip point A
# (docs/insertion.md; by default one horizontal fin at A's height), so the gel splits at A past the rod, as the paper's
# "tissue separation point" says. Runs the needles 10 mm into data/scenes/spacing_study_10mm.json (0.2 mm particles near the
# path, the card at E 0.0748 MPa) for each reach and prints delta and the ratios to SB (docs/notebook/paper_studies.md).
#
#   docs/notebook/scripts/crack_study.sh [OUT] [REACH_mm...]
#       default: out/crack, reaches 1 2
#   NEEDLES="SB LMB AMB HMB" ANGLES="48.6,-55" docs/notebook/scripts/crack_study.sh ...   (default NEEDLES="SB AMB", ANGLES="0"; SB must be among them)
#   LEAD=1 docs/notebook/scripts/crack_study.sh ...      the crack's front 1 mm ahead of A (--crack-lead-mm; default 0)
#   EXTRA="--relaxing-shear-fraction 0.8 --relaxation-time-ms 0.2" docs/notebook/scripts/crack_study.sh ...   another model beside the crack
#
# Two runs at once (one core each). A finished run (OUT/<needle>_r<reach>[_a<angles>][_lead<L>][_<EXTRA words>]/summary.json) is kept, so an
# interrupted study resumes. About 7 min a run with two at once (19 683 particles).
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/crack}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

reaches=("$@")
[ "${#reaches[@]}" -gt 0 ] || reaches=(1 2)
for r in "${reaches[@]}"; do
  study_number crack_study "'$r'" "$r" ">0" "a reach in mm" 1
done
angles="${ANGLES:-0}"
[[ "$angles" =~ ^-?[0-9.]+(,-?[0-9.]+)*$ ]] || { echo "crack_study: ANGLES='$angles' is not a comma-separated list of degrees (e.g. 0 or 48.6,-55)" >&2; exit 2; }
lead="${LEAD:-0}"
study_number crack_study "LEAD='$lead'" "$lead" ">=0" "a length in mm" 1
read -r -a extra <<< "${EXTRA:-}"
suffix=""
[ "$angles" = "0" ] || suffix="_a${angles//,/_}"
[[ "$lead" =~ ^0*\.?0*$ ]] || suffix+="_lead$lead"
for flag in "${extra[@]}"; do suffix+="_${flag#--}"; done  # e.g. _relaxing-shear-fraction_0.8_relaxation-time-ms_0.2

study_needles crack_study

csv="$out/crack_study$suffix.csv"
echo "needle,crack_reach_mm,deflection_mm,bonds_cut_by_crack,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for r in "${reaches[@]}"; do
  flags=(--path-refinement 2 --crack-reach-mm "$r" --crack-angles-deg "$angles" --crack-lead-mm "$lead" "${extra[@]}")
  study_run_two_at_once crack_study "$out" "_r$r$suffix" "${needles[*]}" "${flags[@]}"
  for needle in "${needles[@]}"; do
    s=$(study_summary crack_study "$out/${needle}_r$r$suffix")
    echo "$needle,$r,$(summary_number deflection_mm "$s"),$(summary_number bonds_cut "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

ratio_table "$csv" "reach (mm)"
echo "without a crack (docs/notebook/paper_results/spacing_study_10mm.csv): SB -0.212, LMB +0.045, AMB +0.355, HMB +0.647 mm"
echo "table: $csv; runs in $out/<needle>_r<reach>$suffix"
