#!/usr/bin/env bash
# The main job today: build the paper's four tips, write their reports (JSON), surfaces (STL, glb)
# and pictures (PNG), their half-model T10 meshes (MSH, VTU), the tissue particles (VTP) and the
# tissue card's uniaxial test (CSV, PNG, JSON), the needles' stiffness, a needle run folder and the
# paper's report (the four coupled insertions) into out/, and print the speed-against-error benchmarks.
set -euo pipefail
cd "$(dirname "$0")/.."
# The command and the benchmarks this job runs (scripts/test.sh builds the tests as well).
bash scripts/build.sh needle bench_tip bench_mesh bench_spg bench_needle bench_insertion
mkdir -p out
for preset in SB LMB AMB HMB; do
  ./build/apps/needle tip --preset "$preset" --json --out "out/$preset.stl" > "out/$preset.json"
  ./build/apps/needle tip --preset "$preset" --half --out "out/${preset}_half.glb" --png "out/$preset.png"
  ./build/apps/needle mesh --preset "$preset" --order 2 --size-mm 0.2 --half \
    --out "out/${preset}_half_t10.msh" --out "out/${preset}_half_t10.vtu" --json > "out/${preset}_mesh.json"
done
./build/apps/needle particles --preset SB --insert-mm 5 --out out/tissue_particles.vtp --json > out/tissue_particles.json
./build/apps/needle material-test --csv out/material_test.csv --png out/material_test.png
./build/apps/needle material-test --json > out/material_test.json
./build/apps/needle stiffness --preset LMB --free-length-mm 30 --json > out/stiffness_LMB.json
./build/apps/needle stiffness --preset SB --free-length-mm 30 --json > out/stiffness_SB.json
./build/apps/needle simulate data/scenes/sb_quick.json --out out/sb_quick_run --overwrite
./build/bench/bench_tip 3 | tee out/bench_tip.txt
./build/bench/bench_mesh | tee out/bench_mesh.txt
./build/bench/bench_spg | tee out/bench_spg.txt
./build/bench/bench_needle | tee out/bench_needle.txt
./build/bench/bench_insertion | tee out/bench_insertion.txt
# Speed against error of the fast model level (the default), the four needles 10 mm into the bench scene, against the
# stored reference (about a minute; the full and projection levels' runs, a few minutes a needle, are stored in
# docs/notebook/paper_results/bench_insertion_10mm/: `needle bench insertion --out DIR` runs all three).
./build/apps/needle bench insertion --levels fast --out out/bench_levels --quiet
cat out/bench_levels/speed_error.csv
# The paper reproduced: SB, LMB, AMB and HMB on the paper's scene at the default (fast) model level, with the tissue E
# calibrated on SB at that level (data/paper/calibration_sb.json, made by `needle calibrate`; docs/paper.md) and the
# lip below a tip point crushed 0.48 mm deep, a depth fitted on HMB (data/paper/crushed_depth_hmb.json, which the report
# names with its leave-one-needle-out errors; docs/notebook/crushed_depth.md, refitted in docs/notebook/multirate.md). Each needle's insertion is followed by the
# trucut's third step, the cannula fired over the groove (--fire-cannula; the deflection is the insertion's, bit for
# bit), so the report has both halves of the paper's design rule: the deflection and the sample length I_s. About 2
# minutes a needle on 2 idle cores (about 40 % of it the firing). A run the solver stops is reported as such in the report, not an error of the main job.
# The report sets beside it, from their stored reports in docs/notebook/paper_results/, the tissue mass-scaled to a quarter
# of the needle's step with the lip crushed 0.45 mm (the default until 2026-11-29), the whole lip crushed (the default
# until 2026-11-28), the same at one rate, and the lip kept (before 2026-11-27; docs/notebook/lip_release.md). Three
# replicas of the default model, its runs repeated with the particle lattice shifted 0.1 and 0.05 mm along the needle's
# path and 0.1 mm across it (the cannula fired too), give each deflection's and sample's run-to-run scatter and the
# targets that hold in every replica.
./build/apps/needle paper --calibration data/paper/calibration_sb.json --fire-cannula --out out/paper \
  --label "the default model (the lip crushed 0.48 mm deep, a depth fitted on HMB; the tissue mass-scaled to half the needle's step and stepped multi-rate away from the needle), calibrated on SB" \
  --compare "the tissue mass-scaled to a quarter of the needle's step, the lip crushed 0.45 mm (the default until 2026-11-29)=docs/notebook/paper_results/sampling/results.json" \
  --compare "the whole lip crushed (the default until 2026-11-28)=docs/notebook/paper_results/whole_lip/results.json" \
  --compare "the whole lip crushed, the tissue at one rate (until 2026-11-28, night)=docs/notebook/paper_results/one_rate/results.json" \
  --compare "the lip kept (the default before 2026-11-27)=docs/notebook/paper_results/lip_kept/results.json" \
  --replica "lattice +0.1 mm=docs/notebook/paper_results/half_step_x0.1mm/results.json" \
  --replica "lattice +0.05 mm=docs/notebook/paper_results/half_step_x0.05mm/results.json" \
  --replica "lattice +0.1 mm across the path (y)=docs/notebook/paper_results/half_step_y0.1mm/results.json"
echo "results in out/: <preset>.json (report), <preset>.stl, <preset>_half.glb, <preset>.png,"
echo "  <preset>_half_t10.msh/.vtu + <preset>_mesh.json (T10 mesh and its report), tissue_particles.vtp/.json,"
echo "  material_test.csv/.png/.json (the tissue card in uniaxial tension), stiffness_<preset>.json (tip compliance"
echo "  and bending frequencies), sb_quick_run/ (a run folder: SB pushed through the cannula),"
echo "  paper/ (report.md, results.json, plots and the four run folders with their samples: the paper reproduced),"
echo "  bench_*.txt,"
echo "  bench_levels/ (speed_error.csv/.json/.png: the fast model level against the stored 10 mm reference)"
