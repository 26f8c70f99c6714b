#!/usr/bin/env bash
# Is the deflection converged in the tissue's particle spacing? Runs the paper's needles 10 mm into
# the scene data/scenes/spacing_study_10mm.json (the run defaults, a 16 mm block) with 0.4, 0.2 and
# 0.1 mm particles near the path (--path-refinement 1, 2, 4), then prints delta at 10 mm, the
# particles, the run time, and from the three spacings the observed order of convergence and the
# Richardson estimate of delta at zero spacing (docs/notebook/paper_studies.md: the spacing study).
#
#   docs/notebook/scripts/spacing_study.sh [OUT] [NEEDLES...]     default: out/spacing_study SB AMB
#
# A finished run (OUT/<needle>_r<k>/summary.json) is kept, so an interrupted study resumes. The 0.1 mm
# runs hold 94 185 particles and take 85-100 min each on one core (1.7 GiB); the 0.4 and 0.2 mm runs 5-7 min.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/spacing_study}"
shift || true
needles=("$@")
[ "${#needles[@]}" -gt 0 ] || needles=(SB AMB)
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"

# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

csv="$out/spacing_study.csv"
echo "needle,path_refinement,near_path_spacing_mm,particles,deflection_mm,runtime_s,status" > "$csv.partial"
for needle in "${needles[@]}"; do
  for k in 1 2 4; do
    run="$out/${needle}_r$k"
    study_run spacing_study "$run" "$needle" --path-refinement "$k"
    status=$(summary_status "$run/summary.json")
    echo "$needle,$k,$(awk -v k="$k" 'BEGIN { printf "%g", 0.4 / k }'),$(summary_number particles "$run/summary.json"),$(summary_number deflection_mm "$run/summary.json"),$(summary_number runtime_s "$run/summary.json"),$status" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

# delta_h for h = 0.4, 0.2, 0.1: observed order p = log2((d1 - d2) / (d2 - d4)) where the differences
# shrink with the same sign, and the Richardson estimate d4 + (d4 - d2) / (2^p - 1).
awk -F, 'NR > 1 { d[$1, $2] = $5; n[$1, $2] = $4; t[$1, $2] = $6; s[$1, $2] = $7; if (!($1 in seen)) { seen[$1] = 1; order[++m] = $1 } }
END {
  printf "%-6s %12s %12s %12s %10s %14s\n", "needle", "0.4 mm", "0.2 mm", "0.1 mm", "order p", "delta at h->0"
  for (i = 1; i <= m; ++i) {
    k = order[i]; a = d[k, 1]; b = d[k, 2]; c = d[k, 4]
    q = (b - c) != 0 ? (a - b) / (b - c) : 0
    if (q > 1) { p = log(q) / log(2); est = c + (c - b) / (2 ^ p - 1); ps = sprintf("%.2f", p); es = sprintf("%+.3f", est) }
    else { ps = "n/a"; es = "not converging" }
    printf "%-6s %+12.3f %+12.3f %+12.3f %10s %14s\n", k, a, b, c, ps, es
    printf "%-6s %12s %12s %12s\n", "", sprintf("%d p.", n[k, 1]), sprintf("%d p.", n[k, 2]), sprintf("%d p.", n[k, 4])
    printf "%-6s %12s %12s %12s\n", "", sprintf("%.0f s", t[k, 1]), sprintf("%.0f s", t[k, 2]), sprintf("%.0f s", t[k, 4])
    if (s[k, 1] != "finished" || s[k, 2] != "finished" || s[k, 4] != "finished") printf "%-6s a run stopped: see its summary.json\n", k
  }
}' "$csv"
echo "table: $csv; runs in $out/<needle>_r<1|2|4>"
