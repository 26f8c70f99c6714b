#!/usr/bin/python3
"""Honest calibration of one more parameter (issue 47, item 5; docs/notebook/sensitivity_study.md).

E is calibrated on SB; at most one more parameter may be fitted, on the other needles, and every claim of prediction is
checked on a needle held out. This runs the four paper needles over a list of values of one scene key (everything else
the default model at 30 mm, `needle sweep` with --jobs), and reports, from the ratios to SB (which the calibration of E on
SB leaves as the prediction, delta_X ~ -1.14 mm x ratio_X):
  - for each multi-bevel needle held out, the value fitted to the other two (least squares on their calibrated errors,
    the ratio interpolated linearly between the values run) and the held-out needle's prediction and error;
  - for each single needle the value would be fitted to, the predictions of the other two.

    /usr/bin/python3 studies/sensitivity/second_parameter.py --key needle.groove_start_mm --values 3,4,5,6 --out gs_loo --jobs 2

A key that is a depth into the lip below tip point A (`--lip-depth`, e.g. tissue.separation.lip.depth_mm;
its older spelling tissue.contact.lip_release_depth_mm, which the stored records use, is read the same) acts on a
needle only below that needle's lip thickness: each needle then runs at its own values (`--needle-values HMB=0.2,0.4
AMB=0.1,0.3`) and once with the whole lip crushed (the key set to "whole lip"; the label's value is `default`), and that run stands for it at every value from its lip
thickness (the run's summary.json, lip_release.lip_thickness_mm) on; a needle with no values of its own (SB, no lip)
runs only that once. Between its last value and its lip thickness a needle is interpolated towards its whole-lip run.

Writes into --out: sweep.json and sweep/ (the runs), and second_parameter.json and second_parameter.md (the tables).
`--runs` analyses sweep folders run elsewhere (several: their cases are read by label); `--replica-runs` adds the
same design run on other lattices, and the ratios analysed are the mean over the lattices.
"""
import argparse
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from global_sensitivity import MEASURED_MM, POOLED_SD_MM, StudyError, case_records, write_sweep_file  # noqa: E402

NEEDLES = ["SB", "LMB", "AMB", "HMB"]
MULTI = ["LMB", "AMB", "HMB"]


DEFAULT = "default"  # the label's value of the whole-lip case (--lip-depth; before 2026-11-29 it left the key unset)
WHOLE_LIP = "whole lip"  # a depth key's value for the whole lip (solver/separation/lip_release.h, kWholeLipText)


def sweep_file(key, values, travel_mm, needle_values=None, lip_depth=False):
    """The cases: every needle at every value; or, with needle_values {needle: [values]}, each needle at its own (a needle
    left out runs at none), and with lip_depth each needle once more with the key unset."""
    cases = []
    per_needle = needle_values if needle_values is not None else {n: values for n in NEEDLES}
    if needle_values is None:
        for v in values:
            for n in NEEDLES:
                cases.append({"label": f"{key}={v:g} {n}", "needle.preset": n, key: v})
    else:
        for n in NEEDLES:
            for v in per_needle.get(n, []):
                cases.append({"label": f"{key}={v:g} {n}", "needle.preset": n, key: v})
    if lip_depth:  # the whole lip said outright: since 2026-11-28 a scene's default crushes only its top
        for n in NEEDLES:
            cases.append({"label": f"{key}={DEFAULT} {n}", "needle.preset": n, key: WHOLE_LIP})
    return {"model": "fast", "set": {"motion.travel_mm": travel_mm, "output.frames": 0}, "design": {"cases": cases}}


def read_runs(folders):
    """{needle: {value or DEFAULT: delta_mm}}, {needle: lip thickness (mm) of its unset run}, and the unfinished cases'
    reasons, from the cases of one or more sweep folders (by label; a later folder's case of the same label wins)."""
    deltas, lips, problems = {}, {}, []
    for folder in folders:
        for case_dir, r in case_records(os.path.join(folder, "cases")):
            label = r.get("label", "")
            value_text, needle = label.rsplit(" ", 1)
            text = value_text.split("=", 1)[1]
            value = DEFAULT if text == DEFAULT else float(text)
            if r.get("status") == "finished" and r.get("deflection_mm") is not None:
                deltas.setdefault(needle, {})[value] = r["deflection_mm"]
                if value == DEFAULT:
                    with open(os.path.join(case_dir, "run", "summary.json")) as f:
                        lips[needle] = json.load(f).get("lip_release", {}).get("lip_thickness_mm", 0.0)
            else:
                problems.append(f"{label}: {r.get('status')} {r.get('reason', '')}")
    return deltas, lips, problems


def needle_curve(points, lip_mm=None, unset_mm=None):
    """The needle's delta as a function of the value: linear between the values run; with a lip, its unset run stands
    for every value from the lip's thickness on. None outside the values run."""
    xs = sorted(points)
    if lip_mm is not None and unset_mm is not None:
        xs = [x for x in xs if x < lip_mm]
        points = {**{x: points[x] for x in xs}, lip_mm: unset_mm}
        xs.append(lip_mm)

    def delta(v):
        if lip_mm is not None and unset_mm is not None and v >= lip_mm:
            return unset_mm
        if not xs or v < xs[0] - 1e-12 or v > xs[-1] + 1e-12:
            return None
        for a, b in zip(xs, xs[1:]):
            if v <= b:
                t = (v - a) / (b - a)
                return (1 - t) * points[a] + t * points[b]
        return points[xs[-1]]
    return delta, xs


def ratios_from(deltas, lips, values=None, lip_depth=False):
    """{value: {needle: ratio to SB, delta_SB_mm}} on the values where all four needles are known: every needle run at
    every value; or, with lip_depth, each needle's curve (its values and its unset run) on the union of all values run and
    the lips' thicknesses."""
    ratios = {}
    if not lip_depth:
        for v in values:
            d = {n: deltas.get(n, {}).get(float(v)) for n in NEEDLES}
            if all(x is not None for x in d.values()):
                ratios[float(v)] = {n: d[n] / d["SB"] for n in MULTI}
                ratios[float(v)]["delta_SB_mm"] = d["SB"]
        return ratios
    curves, grid = {}, set()
    for n in NEEDLES:
        runs = {v: x for v, x in deltas.get(n, {}).items() if v != DEFAULT}
        unset = deltas.get(n, {}).get(DEFAULT)
        if unset is None:
            raise StudyError(f"{n}: its run with the key unset did not finish; a lip-depth study needs it")
        curves[n], xs = needle_curve(runs, lips.get(n, 0.0), unset)
        grid.update(xs)
    for v in sorted(grid):
        d = {n: curves[n](v) for n in NEEDLES}
        if all(x is not None for x in d.values()):
            ratios[v] = {n: d[n] / d["SB"] for n in MULTI}
            ratios[v]["delta_SB_mm"] = d["SB"]
    return ratios


def mean_ratios(lattices):
    """The mean over lattices (replicas of the same design, e.g. the particles shifted 0.1 mm in y) of each value's
    ratios and SB's delta, each lattice's as ratios_from gives it; a value is kept only where every lattice has it."""
    common = set(lattices[0])
    for r in lattices[1:]:
        common &= set(r)
    return {v: {k: sum(r[v][k] for r in lattices) / len(lattices) for k in lattices[0][v]} for v in sorted(common)}


def interpolate(ratios, needle, value):
    xs = sorted(ratios)
    if value <= xs[0]:
        return ratios[xs[0]][needle]
    for a, b in zip(xs, xs[1:]):
        if value <= b:
            t = (value - a) / (b - a)
            return (1 - t) * ratios[a][needle] + t * ratios[b][needle]
    return ratios[xs[-1]][needle]


def calibrated(ratio, needle):
    return MEASURED_MM["SB"] * ratio


def fit(ratios, needles, samples=2001):
    """The value (on a fine grid between the values run) whose calibrated predictions of `needles` have the least sum of
    squared errors against the experiment; and whether it lies at an end of the range (not bracketed)."""
    xs = sorted(ratios)
    lo, hi = xs[0], xs[-1]
    best, best_cost = lo, float("inf")
    for k in range(samples):
        v = lo + (hi - lo) * k / (samples - 1)
        cost = sum((calibrated(interpolate(ratios, n, v), n) - MEASURED_MM[n]) ** 2 for n in needles)
        if cost < best_cost:
            best, best_cost = v, cost
    return best, best in (lo, hi)


def analyse(key, ratios):
    if len(ratios) < 2:
        raise StudyError(f"{len(ratios)} values with all four needles finished: the fit needs at least 2")
    held_out = []
    for h in MULTI:
        others = [n for n in MULTI if n != h]
        value, at_end = fit(ratios, others)
        prediction = calibrated(interpolate(ratios, h, value), h)
        held_out.append({"held_out": h, "fitted_on": others, "value": value, "at_range_end": at_end,
                         "prediction_mm": prediction, "error_mm": prediction - MEASURED_MM[h]})
    single = []
    for c in MULTI:
        value, at_end = fit(ratios, [c])
        single.append({"fitted_on": c, "value": value, "at_range_end": at_end,
                       "predictions_mm": {n: calibrated(interpolate(ratios, n, value), n) for n in MULTI},
                       "errors_mm": {n: calibrated(interpolate(ratios, n, value), n) - MEASURED_MM[n] for n in MULTI}})
    return {"key": key, "ratios": {f"{v:g}": r for v, r in sorted(ratios.items())}, "leave_one_out": held_out,
            "fitted_on_one": single, "measured_mm": MEASURED_MM, "two_sd_mm": 2 * POOLED_SD_MM}


def markdown(result):
    key = result["key"]
    md = [f"# One more parameter, `{key}`, fitted honestly", ""]
    md.append("The ratios to SB as run (the default model at 30 mm; E calibrated on SB leaves delta_X = -1.14 mm x ratio_X)"
              + (f", each the mean over {result['lattices']} lattices (--replica-runs):" if result.get("lattices", 1) > 1 else ":"))
    md.append("")
    md.append(f"| {key} | delta_SB (mm) | LMB/SB | AMB/SB | HMB/SB |")
    md.append("|---|---|---|---|---|")
    for v, r in result["ratios"].items():
        md.append(f"| {v} | {r['delta_SB_mm']:+.3f} | {r['LMB']:+.3f} | {r['AMB']:+.3f} | {r['HMB']:+.3f} |")
    md.append(f"| experiment | -1.14 | {MEASURED_MM['LMB'] / -1.14:+.3f} | {MEASURED_MM['AMB'] / -1.14:+.3f} | {MEASURED_MM['HMB'] / -1.14:+.3f} |")
    md.append("")
    md.append("Leave one needle out: the value fitted to the other two multi-bevel needles, and the held-out needle's prediction "
              f"(two standard deviations of the experiment: {result['two_sd_mm']:.2f} mm):")
    md.append("")
    md.append("| held out | fitted on | value | predicted (mm) | measured | error |")
    md.append("|---|---|---|---|---|---|")
    for h in result["leave_one_out"]:
        end = " (range end)" if h["at_range_end"] else ""
        md.append(f"| {h['held_out']} | {', '.join(h['fitted_on'])} | {h['value']:.4g}{end} | {h['prediction_mm']:+.3f} | "
                  f"{MEASURED_MM[h['held_out']]:+.2f} | {h['error_mm']:+.3f} |")
    md.append("")
    md.append("Fitted on one needle, the other two predicted:")
    md.append("")
    md.append("| fitted on | value | LMB error | AMB error | HMB error |")
    md.append("|---|---|---|---|---|")
    for s in result["fitted_on_one"]:
        end = " (range end)" if s["at_range_end"] else ""
        e = s["errors_mm"]
        md.append(f"| {s['fitted_on']} | {s['value']:.4g}{end} | {e['LMB']:+.3f} | {e['AMB']:+.3f} | {e['HMB']:+.3f} |")
    md.append("")
    return "\n".join(md)


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.normpath(os.path.join(here, "..", ".."))
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--key", required=True, help="the scene key of the parameter, e.g. needle.groove_start_mm")
    p.add_argument("--values", help="its values, comma-separated (at least 2), for every needle")
    p.add_argument("--needle-values", nargs="+", metavar="NEEDLE=V,V", default=[],
                   help="each needle's own values instead of --values (with --lip-depth), e.g. HMB=0.2,0.4 AMB=0.1,0.3")
    p.add_argument("--lip-depth", action="store_true",
                   help="the key is a depth into the lip below tip point A: each needle also runs with the key unset, "
                        "which stands for it from its lip's thickness on (see above)")
    p.add_argument("--out", required=True, help="the study folder (created; reruns resume)")
    p.add_argument("--runs", nargs="+", metavar="SWEEP_FOLDER",
                   help="with --analyze-only: the sweep folders to read (default: OUT/sweep)")
    p.add_argument("--replica-runs", nargs="+", metavar="SWEEP_FOLDER", default=[],
                   help="with --analyze-only: each folder the same design run on another lattice (a replica); the ratios "
                        "analysed are the mean over the lattices, as the global study's are")
    p.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--travel-mm", type=float, default=30.0, help="insertion travel (default 30, the paper's)")
    p.add_argument("--needle", default=os.path.join(root, "build", "apps", "needle"), help="the needle command")
    p.add_argument("--analyze-only", action="store_true", help="analyse the finished runs only")
    p.add_argument("--record", metavar="FILE",
                   help="also write the fit's record (what `needle paper --fitted` reads): the value fitted on --fit-on alone, "
                        "rounded to --round, with the leave-one-needle-out table")
    p.add_argument("--fit-on", choices=MULTI, help="with --record: the one needle the value is fitted on")
    p.add_argument("--round", type=float, default=0.01, help="with --record: the shipped value's rounding (default 0.01)")
    p.add_argument("--name", default="", help="with --record: the parameter's name in words, e.g. \"the crushed lip's depth\"")
    p.add_argument("--unit", default="mm", help="with --record: the value's unit (default mm)")
    args = p.parse_args(argv)
    try:
        def numbers(text, what):
            try:
                vs = [float(v) for v in text.split(",") if v.strip()]
            except ValueError:
                raise StudyError(f"{what} {text}: give numbers separated by commas")
            if len(set(vs)) != len(vs):
                raise StudyError(f"{what} {text}: a value is given twice")
            return sorted(vs)
        values, needle_values = [], None
        if args.needle_values:
            if args.values or not args.lip_depth:
                raise StudyError("--needle-values goes with --lip-depth and instead of --values")
            needle_values = {}
            for item in args.needle_values:
                name, _, text = item.partition("=")
                if name not in MULTI:
                    raise StudyError(f"--needle-values {item}: the needle must be one of {', '.join(MULTI)}")
                needle_values[name] = numbers(text, f"--needle-values {name}=")
            values = sorted({v for vs in needle_values.values() for v in vs})
            if len(values) < 2 and not args.analyze_only:
                raise StudyError("--needle-values: give at least two different values in all")
        elif not (args.analyze_only and args.lip_depth):  # a lip-depth study reads its values from its runs
            if not args.values:
                raise StudyError("give --values (or --needle-values with --lip-depth)")
            values = numbers(args.values, "--values")
            if len(values) < 2:
                raise StudyError(f"--values {args.values}: give at least two different values")
        if bool(args.record) != bool(args.fit_on):
            raise StudyError("--record and --fit-on go together")
        if args.round <= 0:
            raise StudyError(f"--round {args.round}: give a positive step")
        if (args.runs or args.replica_runs) and not args.analyze_only:
            raise StudyError("--runs and --replica-runs read finished sweeps: give them with --analyze-only")
        if not args.analyze_only:
            os.makedirs(args.out, exist_ok=True)
            path = write_sweep_file(os.path.join(args.out, "sweep.json"),
                                    sweep_file(args.key, values, args.travel_mm, needle_values, args.lip_depth))
            status = subprocess.call([args.needle, "sweep", path, "--out", os.path.join(args.out, "sweep"), "--jobs", str(args.jobs)])
            if status not in (0, 3):  # 3: some cases did not finish; the values whose four needles did are analysed
                raise StudyError(f"needle sweep exited {status}")
        os.makedirs(args.out, exist_ok=True)
        lattices, problems = [], []
        for folders in [args.runs or [os.path.join(args.out, "sweep")]] + [[f] for f in args.replica_runs]:
            deltas, lips, missing = read_runs(folders)
            lattices.append(ratios_from(deltas, lips, values, args.lip_depth))
            problems += missing
        ratios = mean_ratios(lattices)
        for line in problems:
            print("second_parameter: not finished:", line)
        result = analyse(args.key, ratios)
        result["lattices"] = len(lattices)
        with open(os.path.join(args.out, "second_parameter.json"), "w") as f:
            json.dump(result, f, indent=1)
        if args.record:
            chosen = next(s_ for s_ in result["fitted_on_one"] if s_["fitted_on"] == args.fit_on)
            record = {"description": "A parameter besides E fitted to one paper needle, and the leave-one-needle-out errors "
                                     "that say how well it predicts the needles it was not fitted on "
                                     "(studies/sensitivity/second_parameter.py --record).",
                      "key": args.key, "name": args.name or args.key, "unit": args.unit, "fitted_on": args.fit_on,
                      "value_fitted": chosen["value"], "at_range_end": chosen["at_range_end"],
                      "value": round(round(chosen["value"] / args.round) * args.round, 10),
                      "study": os.path.relpath(os.path.abspath(args.out), root),
                      "predictions_mm": chosen["predictions_mm"], "errors_mm": chosen["errors_mm"],
                      "leave_one_out": result["leave_one_out"], "fitted_on_one": result["fitted_on_one"],
                      "measured_mm": MEASURED_MM, "two_sd_mm": result["two_sd_mm"]}
            with open(args.record, "w") as f:
                json.dump(record, f, indent=1)
                f.write("\n")
        text = markdown(result)
        with open(os.path.join(args.out, "second_parameter.md"), "w") as f:
            f.write(text)
        print(text)
    except StudyError as e:
        print(f"second_parameter: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
