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

Writes into --out: sweep.json and sweep/ (the runs), and second_parameter.json and second_parameter.md (the tables).
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


def sweep_file(key, values, travel_mm):
    cases = []
    for v in values:
        for n in NEEDLES:
            cases.append({"label": f"{key}={v:g} {n}", "needle.preset": n, key: v})
    return {"model": "fast", "set": {"motion.travel_mm": travel_mm, "output.frames": 0}, "design": {"cases": cases}}


def read_ratios(out, key, values):
    """{value: {needle: ratio to SB}} for the values whose four needles finished; and the missing ones' reasons."""
    deltas, problems = {}, []
    for _, r in case_records(os.path.join(out, "sweep", "cases")):
        label = r.get("label", "")
        value_text, needle = label.rsplit(" ", 1)
        value = float(value_text.split("=", 1)[1])
        if r.get("status") == "finished" and r.get("deflection_mm") is not None:
            deltas.setdefault(value, {})[needle] = r["deflection_mm"]
        else:
            problems.append(f"{label}: {r.get('status')} {r.get('reason', '')}")
    ratios = {}
    for v in values:
        d = deltas.get(float(v), {})
        if all(n in d for n in NEEDLES):
            ratios[float(v)] = {n: d[n] / d["SB"] for n in MULTI}
            ratios[float(v)]["delta_SB_mm"] = d["SB"]
    return ratios, problems


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
    md.append("The ratios to SB as run (the default model at 30 mm; E calibrated on SB leaves delta_X = -1.14 mm x ratio_X):")
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
    p.add_argument("--values", required=True, help="its values, comma-separated (at least 2)")
    p.add_argument("--out", required=True, help="the study folder (created; reruns resume)")
    p.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--travel-mm", type=float, default=30.0, help="insertion travel (default 30, the paper's)")
    p.add_argument("--needle", default=os.path.join(root, "build", "apps", "needle"), help="the needle command")
    p.add_argument("--analyze-only", action="store_true", help="analyse the finished runs only")
    args = p.parse_args(argv)
    try:
        try:
            values = [float(v) for v in args.values.split(",") if v.strip()]
        except ValueError:
            raise StudyError(f"--values {args.values}: give numbers separated by commas")
        if len(values) < 2 or len(set(values)) != len(values):
            raise StudyError(f"--values {args.values}: give at least two different values")
        values.sort()
        if not args.analyze_only:
            os.makedirs(args.out, exist_ok=True)
            path = write_sweep_file(os.path.join(args.out, "sweep.json"), sweep_file(args.key, values, args.travel_mm))
            status = subprocess.call([args.needle, "sweep", path, "--out", os.path.join(args.out, "sweep"), "--jobs", str(args.jobs)])
            if status not in (0, 3):  # 3: some cases did not finish; the values whose four needles did are analysed
                raise StudyError(f"needle sweep exited {status}")
        ratios, problems = read_ratios(args.out, args.key, values)
        for line in problems:
            print("second_parameter: not finished:", line)
        result = analyse(args.key, ratios)
        with open(os.path.join(args.out, "second_parameter.json"), "w") as f:
            json.dump(result, f, indent=1)
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
