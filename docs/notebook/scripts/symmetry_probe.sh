#!/usr/bin/env bash
# Is the coupled model biased up or down? The multi-bevel needles deflect too far up (docs/notebook/paper_studies.md); this measures how much
# of that the model itself could carry. Three needles without a groove go 10 mm into data/scenes/spacing_study_10mm.json
# (0.2 mm particles near the path, the card at E 0.0748 MPa), whose particle lattice is symmetric about the path:
#   data/recipes/sb_no_groove.json       SB without its groove
#   data/recipes/sb_upside_down.json     its mirror image in y = 0 (each rotation phi -> 180 - phi, A on the rod's top)
#   data/recipes/symmetric_pyramid.json  four equal facets through A on the axis: up/down symmetric
# Mirror symmetry demands delta(upside down) = -delta(SB) and delta(pyramid) = 0; the script prints both defects.
# tests/solver/test_lspg_insertion.cpp checks the first on a small scene in seconds.
#
#   docs/notebook/scripts/symmetry_probe.sh [OUT]        default OUT: out/symmetry_probe
#
# Two runs at once, then one (one core each). A finished run (OUT/<case>/summary.json) is kept, so an interrupted probe
# resumes. About 6 min a run with three at once.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/symmetry_probe}"
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

cases=(sb_no_groove sb_upside_down symmetric_pyramid)
probe_run() { study_run symmetry_probe "$out/$1" "data/recipes/$1.json" --path-refinement 2 --threads 1 --quiet; }
{ probe_run "${cases[0]}" & }
{ probe_run "${cases[1]}" & }
wait
probe_run "${cases[2]}"

csv="$out/symmetry_probe.csv"
echo "case,deflection_mm,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for c in "${cases[@]}"; do
  s=$(study_summary symmetry_probe "$out/$c")
  echo "$c,$(summary_number deflection_mm "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
done
mv "$csv.partial" "$csv"

awk -F, 'NR > 1 { d[$1] = $2; printf "%-18s %+8.4f mm  (%s)\n", $1, $2, $6 }
  END {
    down = d["sb_no_groove"]; up = d["sb_upside_down"]; pyr = d["symmetric_pyramid"]
    printf "mirror defect: delta(SB) + delta(upside down) = %+.4f mm, %.1f %% of |delta(SB)|\n", down + up, 100 * (down + up) / (down < 0 ? -down : down)
    printf "symmetric tip: delta = %+.4f mm, %.1f %% of |delta(SB)|\n", pyr, 100 * pyr / (down < 0 ? -down : down)
  }' "$csv"
echo "table: $csv; runs in $out/<case>"
