"""Opens a needle run folder in ParaView the way a run is read: the tissue's particles next to the symmetry plane
(z <= 0.45 mm, the layers the half model's needle cuts through) coloured by a field at the run's last frame with a
readable colour bar, the needle in grey, the view on the tissue block from +z (x to the right, y up), and the run's
result written in a corner. The whole tissue stays in the pipeline (the reader `tissue`) for other views.

    pvpython scripts/open_run_in_paraview.py RUN_DIR --state run.pvsm     # then: paraview --state=run.pvsm
    pvpython scripts/open_run_in_paraview.py RUN_DIR --screenshot run.png [--field displacement_mm]
    (without a display: xvfb-run -a pvpython ...)

RUN_DIR is a folder `needle run` or `needle simulate` wrote (tissue.pvd, needle.pvd, summary.json). Fields of the
tissue: von_mises_MPa (the default), displacement_mm, velocity_m_per_s, effective_strain, plastic_strain,
broken_bonds, in_contact. Exit status 2 with one line for a folder that is not a run.
"""
import argparse
import json
import os
import sys

FIELDS = {
    "von_mises_MPa": "von Mises stress (MPa)",
    "displacement_mm": "displacement (mm)",
    "velocity_m_per_s": "velocity (m/s)",
    "effective_strain": "effective strain",
    "plastic_strain": "plastic strain",
    "broken_bonds": "broken bonds",
    "in_contact": "in contact with the needle",
    "in_cannula": "in the fired cannula's bore",
}


def fail(message):
    print("open_run_in_paraview: error: " + message, file=sys.stderr)
    sys.exit(2)


def main():
    parser = argparse.ArgumentParser(description="Open a needle run folder in ParaView, set up to read it.")
    parser.add_argument("run", help="the run folder (tissue.pvd, needle.pvd, summary.json)")
    parser.add_argument("--field", default="von_mises_MPa", choices=sorted(FIELDS), help="the tissue's colour")
    parser.add_argument("--screenshot", help="write the view to this PNG")
    parser.add_argument("--state", help="write a ParaView state (.pvsm) to open with paraview --state=FILE")
    parser.add_argument("--size", default="1600x900", help="picture size in pixels, WxH (default 1600x900)")
    args = parser.parse_args()
    run = os.path.abspath(args.run)
    for name in ("tissue.pvd", "needle.pvd"):
        if not os.path.isfile(os.path.join(run, name)):
            fail(f"'{args.run}' is not a run folder with a tissue: no {name} (needle run and needle simulate write one)")
    if args.screenshot and not args.screenshot.lower().endswith(".png"):
        fail(f"'{args.screenshot}': --screenshot writes a PNG and needs a .png file")
    if args.state and not args.state.lower().endswith(".pvsm"):
        fail(f"'{args.state}': --state writes a ParaView state and needs a .pvsm file")
    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
        assert 100 <= width <= 8000 and 100 <= height <= 8000
    except (ValueError, AssertionError):
        fail(f"--size {args.size}: give WxH in pixels, each from 100 to 8000")
    summary = {}
    try:
        with open(os.path.join(run, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError):
        pass  # an interrupted run may have none; the view still opens
    if args.field == "in_cannula" and summary and "sample" not in summary:
        fail(f"'{args.run}' did not fire the cannula: no in_cannula to colour by (needle run --fire-cannula writes it)")

    from paraview import simple as pv  # imported here so that --help and bad input need no ParaView

    tissue = pv.PVDReader(registrationName="tissue", FileName=os.path.join(run, "tissue.pvd"))
    needle = pv.PVDReader(registrationName="needle", FileName=os.path.join(run, "needle.pvd"))
    view = pv.CreateView("RenderView")
    pv.SetActiveView(view)
    view.ViewSize = [width, height]
    view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 1

    # The last frame: the needle at its deepest.
    scene = pv.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    times = tissue.TimestepValues
    times = list(times) if hasattr(times, "__len__") else [times]
    last = float(times[-1]) if times else 0.0
    scene.AnimationTime = last
    view.ViewTime = last

    near_plane = pv.Clip(registrationName="tissue near the symmetry plane", Input=tissue)
    near_plane.ClipType = "Plane"
    near_plane.ClipType.Origin = [0.0, 0.0, 0.45]
    near_plane.ClipType.Normal = [0.0, 0.0, 1.0]
    near_plane.Invert = 1  # keep z <= 0.45
    shown = pv.Show(near_plane, view)
    shown.SetRepresentationType("Points")
    shown.PointSize = 3.0
    pv.ColorBy(shown, ("POINTS", args.field, "Magnitude"))
    lut = pv.GetColorTransferFunction(args.field)
    lut.ApplyPreset("Viridis (matplotlib)", True)
    shown.RescaleTransferFunctionToDataRange(False, True)
    bar = pv.GetScalarBar(lut, view)
    bar.Title = "tissue: " + FIELDS[args.field]
    bar.ComponentTitle = ""
    bar.TitleColor = [0.0, 0.0, 0.0]
    bar.LabelColor = [0.0, 0.0, 0.0]
    bar.TitleFontSize = 20
    bar.LabelFontSize = 16
    bar.Orientation = "Horizontal"
    bar.ScalarBarLength = 0.5
    bar.WindowLocation = "Lower Center"
    shown.SetScalarBarVisibility(view, True)

    steel = pv.Show(needle, view)
    steel.ColorArrayName = ["POINTS", ""]  # one colour
    steel.DiffuseColor = [0.55, 0.57, 0.62]
    steel.AmbientColor = [0.55, 0.57, 0.62]

    # What the run found, in a corner.
    words = []
    if summary:
        words.append(f"{summary.get('needle', 'needle')}: {summary.get('status', '?')}")
        if isinstance(summary.get("deflection_mm"), (int, float)):
            words.append(f"tip deflection {summary['deflection_mm']:+.3f} mm at {summary.get('insertion_mm', 0):.1f} mm")
        sample = summary.get("sample")
        if isinstance(sample, dict) and isinstance(sample.get("I_s_mm"), (int, float)):
            words.append(f"sample I_s {sample['I_s_mm']:.2f} mm, {sample.get('volume_mm3', 0):.2f} mm3")
        if summary.get("reason"):
            words.append(str(summary["reason"]))
    words.append(f"t = {last:.4g} ms")
    text = pv.Text(registrationName="result", Text="\n".join(words))
    label = pv.Show(text, view)
    label.Color = [0.0, 0.0, 0.0]
    label.FontSize = 18
    label.WindowLocation = "Upper Left Corner"

    # The block as the scene made it (particles flying off do not widen the view), seen from +z with a parallel
    # projection, filling the width.
    x0, x1, y0, y1, z0, z1 = tissue.GetDataInformation().GetBounds()
    try:
        with open(os.path.join(run, "scene.json")) as f:
            block = json.load(f)["tissue"]
        x0 = float(block.get("entry_x_mm", 0.0))
        x1 = x0 + float(block["size_mm"][0])
        y0, y1 = -0.5 * float(block["size_mm"][1]), 0.5 * float(block["size_mm"][1])
    except (OSError, ValueError, KeyError, TypeError, IndexError):
        pass  # the data's own bounds
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    pv.Render(view)  # the first render resets the camera: place it after
    view.CameraFocalPoint = [cx, cy, 0.0]
    view.CameraPosition = [cx, cy, 10.0 * max(x1 - x0, y1 - y0, 1.0)]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraParallelProjection = 1
    view.CameraParallelScale = 0.5 * max(y1 - y0, (x1 - x0) * height / width) * 1.15
    pv.Render(view)

    if args.screenshot:
        pv.SaveScreenshot(args.screenshot, view, ImageResolution=[width, height])
        print("open_run_in_paraview: wrote " + args.screenshot)
    if args.state:
        pv.SaveState(args.state)
        print("open_run_in_paraview: wrote " + args.state)
    if not args.screenshot and not args.state:
        print("open_run_in_paraview: nothing written; give --state FILE.pvsm (then paraview --state=FILE.pvsm) or --screenshot FILE.png")


if __name__ == "__main__":
    main()
