#!/usr/bin/env bash
# Does a gel that relaxes move the balance of the tips' loads? The card is elastic: the tissue pressed down
# under the shaft behind tip point A pushes the multi-bevel needles up as hard after 3 ms as when the tip
# passed. A viscoelastic gel (--relaxing-shear-fraction g, --relaxation-time-ms tau; solver/tissue_material.h)
# lets that held load relax while the tip's fresh loads do not. Runs SB and AMB 10 mm into
# data/scenes/spacing_study_10mm.json (0.2 mm particles near the path, the card at E 0.0748 MPa) for each
# variant g:tau and prints delta and AMB / SB (docs/notebook/paper_studies.md). The tip passes 1 mm in 0.125 ms at 8 m/s,
# and reaches 10 mm at 1.6 ms.
#   0          no relaxation (the card)
#   g:tau      a share g of the shear stress relaxes with time constant tau ms, e.g. 0.5:0.5
#
#   docs/notebook/scripts/relaxation_study.sh [OUT] [VARIANT...]
#       default: out/relaxation, variants 0 0.5:0.5 0.8:0.2
#
# SB and AMB of a variant run at once (one core each). A finished run (OUT/<needle>_g<g>_tau<tau>/summary.json)
# is kept, so an interrupted study resumes. About 10 min a run (19 683 particles).
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/relaxation}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"

variants=("$@")
[ "${#variants[@]}" -gt 0 ] || variants=(0 0.5:0.5 0.8:0.2)
for v in "${variants[@]}"; do
  [[ "$v" =~ ^0$|^0?\.[0-9]+:[0-9]*\.?[0-9]+$ ]] || { echo "relaxation_study: '$v' is not 0 or g:tau (g in [0, 1), tau in ms, e.g. 0.5:0.5)" >&2; exit 2; }
done

# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

name_of() {  # the run folder's suffix: g0.5_tau0.5, or elastic
  [ "$1" = 0 ] && { echo elastic; return 0; }
  echo "g${1%%:*}_tau${1##*:}"
}
flags_of() {  # the run flags of a variant
  [ "$1" = 0 ] && return 0
  echo "--relaxing-shear-fraction ${1%%:*} --relaxation-time-ms ${1##*:}"
}

csv="$out/relaxation_study.csv"
echo "needle,relaxing_shear_fraction,relaxation_time_ms,deflection_mm,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for v in "${variants[@]}"; do
  # shellcheck disable=SC2046  # flags are words
  { study_run relaxation_study "$out/SB_$(name_of "$v")" SB --path-refinement 2 $(flags_of "$v") & }
  # shellcheck disable=SC2046
  { study_run relaxation_study "$out/AMB_$(name_of "$v")" AMB --path-refinement 2 $(flags_of "$v") & }
  wait
  for needle in SB AMB; do
    s="$out/${needle}_$(name_of "$v")/summary.json"
    [ -f "$s" ] || { echo "relaxation_study: no summary in $out/${needle}_$(name_of "$v")" >&2; exit 1; }
    g=0 tau=
    [ "$v" = 0 ] || g="${v%%:*}" tau="${v##*:}"
    echo "$needle,$g,$tau,$(summary_number deflection_mm "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"

awk -F, 'NR > 1 { k = $2 == 0 ? "0 (elastic)" : $2 ":" $3; d[$1, k] = $4; s[$1, k] = $8; if (!(k in seen)) { seen[k] = 1; order[++m] = k } }
END {
  printf "%-14s %10s %10s %9s   %s\n", "g:tau (ms)", "SB", "AMB", "AMB/SB", "(delta in mm at 10 mm)"
  for (i = 1; i <= m; ++i) {
    k = order[i]
    printf "%-14s %+10.3f %+10.3f %9.2f", k, d["SB", k], d["AMB", k], d["SB", k] != 0 ? d["AMB", k] / d["SB", k] : 0
    if (s["SB", k] != "finished" || s["AMB", k] != "finished") printf "   a run stopped: see its summary.json"
    printf "\n"
  }
  printf "%-14s %10s %10s %9s\n", "experiment", "-1.14", "+0.24", "-0.21 (at 30 mm)"
}' "$csv"
echo "table: $csv; runs in $out/<needle>_g<g>_tau<tau> (elastic: no relaxation)"
