#!/usr/bin/env bash
# scripts/open_run_in_paraview.py opens a real run folder: a short coupled run (the regression scene SB into a small
# block), then ParaView (pvpython under a virtual X server) writes the picture and the state; the picture has the
# size asked and the colours of a drawn scene, the state loads back with the run's sources, and a folder that is not
# a run is refused with exit 2 and one line. Usage: open_run_in_paraview_test.sh NEEDLE_BINARY SOURCE_DIR
# Exit 77 (skipped) where pvpython or xvfb-run is missing (scripts/install-deps.sh installs both).
set -euo pipefail
needle="$1"
source_dir="$2"
if ! command -v pvpython > /dev/null || ! command -v xvfb-run > /dev/null; then
  echo "skipped: pvpython or xvfb-run is not installed"
  exit 77
fi
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
script="$source_dir/scripts/open_run_in_paraview.py"
"$needle" simulate "$source_dir/data/scenes/regression/sb.json" --out "$dir/run" --quiet
# pvpython under a virtual X server. On a loaded machine its first connection to a fresh Xvfb now and then fails
# ("bad X server connection", in a second and before anything is written): up to five tries.
paraview() {
  local try
  for try in 1 2 3 4 5; do
    if xvfb-run -a -s "-screen 0 1920x1080x24" pvpython "$@"; then return 0; fi
    echo "pvpython under xvfb-run failed (try $try of 5)"
    sleep 2
  done
  return 1
}
paraview "$script" "$dir/run" --screenshot "$dir/run.png" --state "$dir/run.pvsm" --size 1200x700
cat > "$dir/check.py" << PY
import vtk
from vtk.util.numpy_support import vtk_to_numpy
from paraview.simple import LoadState, GetSources
r = vtk.vtkPNGReader()
r.SetFileName("$dir/run.png")
r.Update()
image = r.GetOutput()
pixels = vtk_to_numpy(image.GetPointData().GetScalars())[:, :3]
colours = len(set(map(tuple, pixels.tolist())))
LoadState("$dir/run.pvsm")
names = sorted(k[0] for k in GetSources().keys())
print(image.GetDimensions()[0], image.GetDimensions()[1], colours, names)
assert image.GetDimensions()[:2] == (1200, 700), "picture size"
assert colours > 50, "a drawn scene has more than 50 colours (particles in viridis, the shaded needle, the text)"
assert any("tissue.pvd" in n for n in names) and any("needle.pvd" in n for n in names), "the state holds the run's readers"
PY
paraview "$dir/check.py"
# Not a run: one line, exit 2, nothing written.
mkdir "$dir/empty"
set +e
out="$(pvpython "$script" "$dir/empty" --state "$dir/empty.pvsm" 2>&1)"
code=$?
set -e
echo "$out"
[ "$code" -eq 2 ] && [ "$(printf '%s\n' "$out" | wc -l)" -eq 1 ] && [ ! -e "$dir/empty.pvsm" ]
echo "open_run_in_paraview: passed"
