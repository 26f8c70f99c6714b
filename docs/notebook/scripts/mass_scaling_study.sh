#!/usr/bin/env bash
# How far does the default (fast) level's tissue mass scaling move the paper's needles at 30 mm? The fast level
# gives every particle whose own stable step falls below a target the mass that brings it there
# (solver.tissue_mass_scaling_dt_ms; by default the implicit needle's step, 0.002 ms). Runs `needle run` (the default
# model, the shipped calibration on SB, E 0.0884 MPa) for each needle and target, one after another on THREADS threads
# (default 2), and writes OUT/mass_scaling_study.csv (docs/notebook/lip_release.md, "The mass scaling"):
#
#   docs/notebook/scripts/mass_scaling_study.sh [OUT] [TARGET_MS...]
#       default: out/mass_scaling, targets 0.001 0.0005 (the default's 0.002 is the stored report); NEEDLES="SB HMB"
#       (default); a target "off" runs without mass scaling (solver.tissue_mass_scaling=false: 25-30 min a needle);
#       EXTRA="--set ..." adds settings (e.g. another E)
#
# A finished run (OUT/<needle>_<target>/summary.json) is kept, so an interrupted study resumes. About 1.5-4 min a run
# at 0.001 and 0.0005 on two threads.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out="${1:-out/mass_scaling}"
shift || true
[ -x build/apps/needle ] || bash scripts/build.sh
mkdir -p "$out"
targets=("$@")
[ "${#targets[@]}" -gt 0 ] || targets=(0.001 0.0005)
read -r -a needles <<< "${NEEDLES:-SB HMB}"
threads="${THREADS:-2}"
extra="${EXTRA:-}"
for t in "${targets[@]}"; do
  [[ "$t" == off || "$t" =~ ^[0-9]*\.?[0-9]+$ ]] || { echo "mass_scaling_study: '$t' is not a target step in ms (e.g. 0.0005) or off" >&2; exit 2; }
done

# shellcheck source=docs/notebook/scripts/study_helpers.sh
source docs/notebook/scripts/study_helpers.sh

for t in "${targets[@]}"; do
  for n in "${needles[@]}"; do
    run="$out/${n}_$t"
    [ -f "$run/summary.json" ] && continue
    setting="solver.tissue_mass_scaling_dt_ms=$t"
    [ "$t" != off ] || setting="solver.tissue_mass_scaling=false"
    # shellcheck disable=SC2086
    ./build/apps/needle run --preset "$n" --set "$setting" $extra --frames 0 --threads "$threads" --quiet --out "$run" --overwrite \
      > "$run.log" 2>&1 || true
  done
done

csv="$out/mass_scaling_study.csv"
echo "needle,target_ms,deflection_mm,max_mass_ratio,max_mass_ratio_crushed,max_added_mass_percent,coupling_steps,max_energy_balance_error,runtime_s,status" > "$csv.partial"
for t in "${targets[@]}"; do
  for n in "${needles[@]}"; do
    s="$(study_summary mass_scaling_study "$out/${n}_$t")" || continue
    echo "$n,$t,$(summary_number deflection_mm "$s"),$(summary_number max_mass_ratio "$s"),$(summary_number max_mass_ratio_crushed "$s"),$(summary_number max_added_mass_percent "$s"),$(summary_run_fields "$s")" >> "$csv.partial"
  done
done
mv "$csv.partial" "$csv"
cat "$csv"
