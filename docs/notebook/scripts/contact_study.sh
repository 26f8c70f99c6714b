#!/usr/bin/env bash
# Is delta converged in the penalty contact? The contact (solver/needle_tissue_contact.h) holds each particle `skin` off the
# needle's surface with a penalty `stiffness_factor` times the particle's own stiffness: two numerical parameters, whose
# exact-contact limit is skin 0 and an infinite stiffness. The particle-spacing study (docs/notebook/scripts/spacing_study.sh) keeps both
# fixed, so it cannot see their error. Runs the needles 10 mm into data/scenes/spacing_study_10mm.json (0.2 mm particles near
# the path, the card at E 0.0748 MPa) for each skin at the given stiffness factor and prints delta and the ratios to SB
# (docs/notebook/paper_studies.md).
#
#   docs/notebook/scripts/contact_study.sh [OUT] [SKIN_mm...]
#       default: out/contact, skins 0.02; the 0.04 of the study scene comes from the spacing study
#   K=30 docs/notebook/scripts/contact_study.sh ...                             (the stiffness factor; default 10, the 10 mm study scene's; the run default is 30)
#   NEEDLES="SB LMB AMB HMB" docs/notebook/scripts/contact_study.sh ...          (default NEEDLES="SB AMB"; SB must be among them)
#
# Two runs at once (one core each). A finished run (OUT/<needle>_s<skin>_k<K>/summary.json) is kept, so an interrupted study
# resumes. About 9 min a run at K 10 with two at once (19 683 particles); a stiffer penalty takes about sqrt(K / 10) times
# the tissue steps.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/contact}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

k="${K:-10}"
study_number contact_study "K='$k'" "$k" ">0" "a stiffness factor" 30
skins=("$@")
[ "${#skins[@]}" -gt 0 ] || skins=(0.02)
for s in "${skins[@]}"; do
  study_number contact_study "'$s'" "$s" ">=0" "a skin in mm" 0.02
done

study_needles contact_study

csv="$out/contact_study_k$k.csv"
echo "needle,skin_mm,deflection_mm,max_penetration_mm,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for s in "${skins[@]}"; do
  study_run_two_at_once contact_study "$out" "_s${s}_k$k" "${needles[*]}" --path-refinement 2 --contact-skin-mm "$s" --contact-stiffness-factor "$k"
  for needle in "${needles[@]}"; do
    f=$(study_summary contact_study "$out/${needle}_s${s}_k$k")
    echo "$needle,$s,$(summary_number deflection_mm "$f"),$(summary_number max_penetration_mm "$f"),$(summary_run_fields "$f")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

ratio_table "$csv" "skin (mm), K $k"
echo "the study scene's contact (the run default until 2026-11-24), skin 0.04 mm and K 10 (docs/notebook/paper_results/spacing_study_10mm.csv): SB -0.212, LMB +0.045, AMB +0.355, HMB +0.647 mm"
echo "table: $csv; runs in $out/<needle>_s<skin>_k$k"
