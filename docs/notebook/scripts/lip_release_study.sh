#!/usr/bin/env bash
# Does releasing the lip below tip point A give the measured LMB -> AMB plateau? The lip release
# (tissue.contact.lip_release_below_mm and lip_release_depth_mm, solver/separation/lip_release.h) cuts loose the
# tissue the tip meets from BELOW to BELOW + DEPTH under A, inside the rod's outline. Runs the paper scene at
# 30 mm (the default model, the shipped calibration on SB: E 0.0884 MPa) for each needle and case, two runs at
# once on one thread each, and writes OUT/lip_release_study.csv (docs/notebook/lip_release.md):
#
#   docs/notebook/scripts/lip_release_study.sh [OUT] [BELOW_MM,DEPTH_MM...]
#       default: out/lip_release, cases 0,0.45 0,0.2 (the lip's top released) and 0.2,1 0.3,1 (a lip's part
#       deeper than 0.2 or 0.3 mm released); NEEDLES="LMB AMB HMB" (SB's tip point is on the rod's bottom: it has
#       no lip, and the release leaves it as it is; NEEDLES="SB" checks that); MODE=crushed or off (default free)
#       keeps the band's bonds and takes its shear stiffness (tissue.contact.lip_release_mode); a replica:
#       TAG=x0.1 EXTRA="--set tissue.entry_x_mm=0.1" (the lattice shifted; TAG names its folders and table)
#
# A finished run (OUT/<needle>_b<below>_d<depth>/summary.json) is kept, so an interrupted study resumes. About
# 1.5-3 min a run with two at once.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/lip_release}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
cases=("$@")
[ "${#cases[@]}" -gt 0 ] || cases=(0,0.45 0,0.2 0.2,1 0.3,1)
read -r -a needles <<< "${NEEDLES:-LMB AMB HMB}"
mode="${MODE:-free}"
[[ "$mode" == free || "$mode" == crushed || "$mode" == off ]] || { echo "lip_release_study: MODE='$mode' is not free, crushed or off" >&2; exit 2; }
suffix=""
[ "$mode" = free ] || suffix="_$mode"
[ -z "${TAG:-}" ] || suffix="${suffix}_$TAG"
extra="${EXTRA:-}"
for c in "${cases[@]}"; do
  [[ "$c" =~ ^[0-9]*\.?[0-9]+,[0-9]*\.?[0-9]+$ ]] || { echo "lip_release_study: '$c' is not BELOW_MM,DEPTH_MM (e.g. 0.2,1)" >&2; exit 2; }
done

# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

run_one() {  # NEEDLE BELOW DEPTH
  local run="$out/$1_b$2_d$3$suffix"
  [ -f "$run/summary.json" ] && return 0
  ./build/apps/needle run --preset "$1" --set "tissue.contact.lip_release_below_mm=$2" --set "tissue.contact.lip_release_depth_mm=$3" \
    --set "tissue.contact.lip_release_mode=$mode" $extra \
    --threads 1 --quiet --out "$run" --overwrite > "$run.log" 2>&1 || true
}
export -f run_one
export out mode suffix extra
jobs=()
for c in "${cases[@]}"; do for n in "${needles[@]}"; do jobs+=("$n ${c/,/ }"); done; done
printf '%s\n' "${jobs[@]}" | xargs -P 2 -L 1 bash -c 'run_one "$0" "$1" "$2"'

csv="$out/lip_release_study_$mode${TAG:+_$TAG}.csv"
echo "needle,lip_release_mode,lip_release_below_mm,lip_release_depth_mm,deflection_mm,particles_released,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for c in "${cases[@]}"; do
  for n in "${needles[@]}"; do
    s="$(study_summary lip_release_study "$out/${n}_b${c/,/_d}$suffix")" || continue
    echo "$n,$mode,$c,$(summary_number deflection_mm "$s"),$(summary_number particles_released "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"
cat "$csv"
