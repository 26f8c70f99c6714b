#!/usr/bin/env bash
# Is the paper's tissue block wide enough? Its half block is 8 mm high and 2 mm wide, with the faces
# y = +-4 and z = 2 fixed: 1.5 mm of gel between the rod and the side wall. The experiment's phantom was
# 100 mm long, 80 mm wide and 30 mm high. Runs SB and AMB 10 mm into data/scenes/spacing_study_10mm.json (0.2 mm particles near
# the path, the card at E 0.0748 MPa) in blocks of growing height and width, and prints delta and AMB / SB
# for each (docs/notebook/paper_studies.md):
#   paper    16 x 8 x 2 mm   (the paper's cross-section; the scene's own block)
#   y16z6    16 x 16 x 6 mm  (--tissue-size-mm 16,16,6)
#   y24z10   16 x 24 x 10 mm (--tissue-size-mm 16,24,10)
#
#   docs/notebook/scripts/domain_study.sh [OUT] [BLOCK...]
#       default: out/domain, every block
#
# A finished run (OUT/<needle>_<block>/summary.json) is kept, so an interrupted study resumes. The
# particles outside the 0.2 mm band are 0.4 mm apart, so a larger block costs more: 19 683, 72 333 and
# 157 383 particles; about 7, 10 and 20 min on one core.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/domain}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"

declare -A block_flags=([paper]="" [y16z6]="--tissue-size-mm 16,16,6" [y24z10]="--tissue-size-mm 16,24,10")
blocks=("$@")
[ "${#blocks[@]}" -gt 0 ] || blocks=(paper y16z6 y24z10)
for block in "${blocks[@]}"; do
  [ -n "${block_flags[$block]+set}" ] || { echo "domain_study: unknown block '$block' (paper, y16z6, y24z10)" >&2; exit 2; }
done

# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

csv="$out/domain_study.csv"
echo "needle,block,size_mm,particles,deflection_mm,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for needle in SB AMB; do
  for block in "${blocks[@]}"; do
    flags="${block_flags[$block]}"
    run="$out/${needle}_${block}"
    # shellcheck disable=SC2086  # flags are words
    study_run domain_study "$run" "$needle" --path-refinement 2 $flags
    # the tissue's size_mm is the scene's only array-valued size_mm; scene.json spreads it over lines
    size=$(tr -d '[:space:]' < "$run/scene.json" | grep -o '"size_mm":\[[^]]*\]' | head -1 | sed 's/.*\[//; s/\]//; s/,/ x /g')
    echo "$needle,$block,$size,$(summary_number particles "$run/summary.json"),$(summary_number deflection_mm "$run/summary.json"),$(summary_run_fields "$run/summary.json")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

awk -F, 'NR > 1 { d[$1, $2] = $5; z[$2] = $3; s[$1, $2] = $9; if (!($2 in seen)) { seen[$2] = 1; order[++m] = $2 } }
END {
  printf "%-8s %-18s %10s %10s %9s   %s\n", "block", "size (mm)", "SB", "AMB", "AMB/SB", "(delta in mm at 10 mm)"
  for (i = 1; i <= m; ++i) {
    k = order[i]
    printf "%-8s %-18s %+10.3f %+10.3f %9.2f", k, z[k], d["SB", k], d["AMB", k], d["SB", k] != 0 ? d["AMB", k] / d["SB", k] : 0
    if (s["SB", k] != "finished" || s["AMB", k] != "finished") printf "   a run stopped: see its summary.json"
    printf "\n"
  }
  printf "%-8s %-18s %10s %10s %9s\n", "experiment", "100 x 30 x 40 (half)", "-1.14", "+0.24", "-0.21 (at 30 mm)"
}' "$csv"
echo "table: $csv; runs in $out/<needle>_<block>"
