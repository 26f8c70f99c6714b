#!/usr/bin/env bash
# Does a slit in the symmetry plane move the balance of the tips' loads? The needle's cut separates the
# tissue along its own surface, whose normals lie in the symmetry plane, so the tissue on the plane is
# pushed only up or down; a split in the plane (--slit-half-height-mm, solver/symmetry_slit.h) lets the rod
# push it aside. Runs SB and AMB 10 mm into data/scenes/spacing_study_10mm.json (0.2 mm particles near the
# path, the card at E 0.0748 MPa) with slits of growing height, and prints delta and AMB / SB for each
# (docs/notebook/paper_studies.md):
#   0      no slit (the default model)
#   0.5    as tall as the rod (its radius either side of the axis)
#   1.0    twice the rod's height
#
#   docs/notebook/scripts/slit_study.sh [OUT] [HALF_HEIGHT_MM...]
#       default: out/slit, heights 0 0.5 1.0
#
# A finished run (OUT/<needle>_h<height>/summary.json) is kept, so an interrupted study resumes. About
# 10 min a run on one core (19 683 particles).
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/slit}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"

heights=("$@")
[ "${#heights[@]}" -gt 0 ] || heights=(0 0.5 1.0)
for h in "${heights[@]}"; do
  [[ "$h" =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "slit_study: '$h' is not a half height in mm (e.g. 0.5)" >&2; exit 2; }
done

# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

csv="$out/slit_study.csv"
echo "needle,slit_half_height_mm,deflection_mm,particles_opened,mean_opening_mm,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for needle in SB AMB; do
  for h in "${heights[@]}"; do
    run="$out/${needle}_h$h"
    study_run slit_study "$run" "$needle" --path-refinement 2 --slit-half-height-mm "$h"
    s="$run/summary.json"
    echo "$needle,$h,$(summary_number deflection_mm "$s"),$(summary_number particles_opened "$s"),$(summary_number mean_opening_mm "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

awk -F, 'NR > 1 { d[$1, $2] = $3; n[$1, $2] = $4; s[$1, $2] = $9; if (!($2 in seen)) { seen[$2] = 1; order[++m] = $2 } }
END {
  printf "%-14s %10s %10s %9s %16s   %s\n", "slit (mm)", "SB", "AMB", "AMB/SB", "opened SB / AMB", "(delta in mm at 10 mm)"
  for (i = 1; i <= m; ++i) {
    k = order[i]
    printf "%-14s %+10.3f %+10.3f %9.2f %16s", k, d["SB", k], d["AMB", k], d["SB", k] != 0 ? d["AMB", k] / d["SB", k] : 0, n["SB", k] " / " n["AMB", k]
    if (s["SB", k] != "finished" || s["AMB", k] != "finished") printf "   a run stopped: see its summary.json"
    printf "\n"
  }
  printf "%-14s %10s %10s %9s\n", "experiment", "-1.14", "+0.24", "-0.21 (at 30 mm)"
}' "$csv"
echo "table: $csv; runs in $out/<needle>_h<height>"
