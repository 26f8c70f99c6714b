#!/usr/bin/python3
"""The global sensitivity study of the paper's unknowns (issue 47; docs/notebook/sensitivity_study.md).

Every unknown of the study file (data/studies/global_sensitivity.json) is varied at once over its range on a Sobol'
low-discrepancy design (OpenTURNS). Each design point is run on the four paper needles at 30 mm through
`needle sweep` (worker processes, or MPI with --mpi N), one sweep per batch of points, so batch k+1 extends the study
without moving batches 0..k. The analysis ranks the factors by their HSIC indices (OpenTURNS, with permutation
p-values) for each response (the four deflections and each multi-bevel needle's ratio to SB, which a calibration of E
on SB leaves as the prediction: delta_X ~ -1.14 mm * ratio) and fits a kriging surrogate of the ratios on the factors
that matter, with its leave-one-out error, to find how far the admissible box can move them. A study file's
"replicas" run every point again with scene keys set on top (the lattice shifted): a response is then the mean of a
point's runs, and the scatter between them, pooled over the points, is the runs' noise the kriging smooths and the
surrogates are validated against.

    /usr/bin/python3 studies/sensitivity/global_sensitivity.py --out study --batches 2 --jobs 2   # design, run, analyse
    /usr/bin/python3 studies/sensitivity/global_sensitivity.py --out study --analyze-only         # the tables again
    /usr/bin/python3 studies/sensitivity/global_sensitivity.py --out study --batches 2 --points 8  # batch 1's first 8 points
    /usr/bin/python3 studies/sensitivity/global_sensitivity.py --out study --batch 2              # batch 2 alone (the corners)
    /usr/bin/python3 studies/sensitivity/global_sensitivity.py --out study --analyze-only --region crushed_depth_mm=0.43,0.8
                                                            # the points of a region of the box alone (study_region.py)

A study file's "kriging_trend" ("constant", the default, or "linear") is the surrogates' trend; its "held_out":
{"from_batch": K} adds the held-out check (study_held_out.py): the procedure fitted on batches 0..K-1 predicts the
points of batch K on, from the design, before they run (analysis/held_out.csv), and is judged on them as they complete.
Its "corners" make one batch the box's corners in the named factors (study_design.read_corners), predicted the same way
from the points below "fitted_on_points_below" (analysis/corners_held_out.csv) and then part of the fit. Its
"points_held_out": {"points": [a, b]} predicts the points a..b-1 from every other complete point
(analysis/points_held_out.csv): a held-out round for the surrogates as refitted after the earlier checks.

Writes into --out: batch_K/sweep.json (the sweep file of batch K) and batch_K/sweep/ (its sweep folder), the same in
batch_K_NAME/ for each replica NAME, and
analysis/: points.csv (one row a design point: the factors, each needle's deflection, groove fill and floor contact,
the ratios), hsic.csv and hsic.md (R2-HSIC index and p-value of every factor for every response), surrogate.json
(the kriging surrogates, their leave-one-out Q2 and the box's reach), hsic.png and ratio_scatter.png.
Python, not C++: the statistics are OpenTURNS's (python3-openturns), and the runs are the `needle` command's.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_design import (StudyError, batch_cases, batch_folder, corner_units, factor_value, numeric, read_points_held_out, read_study,  # noqa: E402,F401
                          replica_names, replica_set, sweep_file, unit_design, write_batch, write_sweep_file)
from study_runs import (MEASURED_MM, PLATEAU, POOLED_SD_MM, case_records, complete_rows, point_runs, read_points,  # noqa: E402,F401
                        replica_scatter, response_view, responses, within_point_scatter)
from study_held_out import held_out_checks, write_held_out  # noqa: E402
from study_region import parse_region, region_label, region_study  # noqa: E402
from study_surrogates import (MIN_Q2, RMSE_OVER_SCATTER, chaos_or_none, hsic_indices, joint_search,  # noqa: E402,F401
                              kriging_surrogate, run_distances)


def run_batch(args, sweep_path):
    folder = os.path.join(os.path.dirname(sweep_path), "sweep")
    if args.mpi:
        command = ["mpirun", "-n", str(args.mpi + 1), "--bind-to", "none", "--oversubscribe"]
        if os.geteuid() == 0:
            command.append("--allow-run-as-root")
        command += [args.needle, "sweep", sweep_path, "--out", folder]
    else:
        command = [args.needle, "sweep", sweep_path, "--out", folder, "--jobs", str(args.jobs)]
    if args.threads:
        command += ["--threads", str(args.threads)]
    if args.allow_other_code:
        command.append("--allow-other-code")
    print("global_sensitivity:", " ".join(command), flush=True)
    status = subprocess.call(command)
    if status == 3:  # the table is written; some cases stopped or failed: the analysis leaves their points out
        print(f"global_sensitivity: some cases of {sweep_path} did not finish; their points are left out", flush=True)
    elif status != 0:
        raise StudyError(f"needle sweep exited {status} for {sweep_path}")


def reach_words(surrogate):
    """" (extrapolated: ...)" where a box extreme lies farther from every run point than the runs lie from each other
    (run_distances): its value is the surrogate's trend, not something the runs have seen."""
    far = [(k, surrogate[k]) for k in ("box_min", "box_max") if surrogate[k].get("extrapolated")]
    if not far:
        return ""
    return (" (extrapolated: " + ", ".join(f"{k[4:]} {d['nearest_run']:.2f} from the nearest run" for k, d in far)
            + f", the runs {far[0][1]['run_spacing']:.2f} apart)")


def replica_lines(study, rows, within, report_scatter):
    """The Markdown lines on each point's own runs: one run's scatter pooled over the points beside the paper report's,
    the share of the single runs' variance that lies within points (what the factors cannot explain), and the points
    whose runs differ most."""
    names = replica_names(study)
    lines = [f"Each point runs {len(names)} times (the plain run and {', '.join(names[1:])}); a response is their mean. "
             "The scatter between a point's own runs, pooled over the points:", "",
             "| response | one run's SD, within points (dof) | the paper report's replicas' SD | share of the runs' variance within points | largest difference (point) |",
             "|---|---|---|---|---|"]
    for r, (sd, dof) in within.items():
        runs = [(point_runs(study, row, r), row["point"]) for row in rows]
        singles = [v for values, _ in runs for v in values]
        total = statistics.variance(singles) if len(singles) >= 2 else float("nan")
        pairs = [(max(values) - min(values), point) for values, point in runs if len(values) >= 2]
        widest = max(pairs) if pairs else (float("nan"), "-")
        lines.append(f"| {r} | {sd:.3f} ({dof}) | " + (f"{report_scatter[r]:.3f}" if r in report_scatter else "-")
                     + (f" | {sd * sd / total:.2f}" if total > 0 else " | -") + f" | {widest[0]:.3f} ({widest[1]}) |")
    lines.append("")
    return lines


def write_csv(path, rows):
    if not rows:
        return
    columns = list(rows[0].keys())
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        for r in rows:
            w.writerow(r)
    os.replace(path + ".tmp", path)


def plot_hsic(path, study, table, response_names):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [f["name"] for f in study["factors"]]
    fig, ax = plt.subplots(figsize=(11, 5.5))
    width = 0.8 / len(response_names)
    for k, resp in enumerate(response_names):
        values = [table[resp][n][0] if n in table[resp] else 0.0 for n in names]  # a factor that cannot act on it: none
        ax.bar([i + k * width for i in range(len(names))], values, width, label=resp)
        for i, n in enumerate(names):
            if n in table[resp] and table[resp][n][1] < 0.05:
                ax.text(i + k * width, values[i], "*", ha="center", va="bottom", fontsize=9)
    ax.set_xticks([i + 0.4 - width / 2 for i in range(len(names))])
    ax.set_xticklabels(names, rotation=40, ha="right", fontsize=8)
    ax.set_ylabel("R2-HSIC index")
    ax.set_title("Which unknowns move the deflections and the ratios to SB (* permutation p < 0.05)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_scatter(path, study, views, table):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ratios = [r for r in responses(study) if r.startswith("ratio_")]
    fig, axes = plt.subplots(len(ratios), 3, figsize=(12, 3.2 * len(ratios)), squeeze=False)
    for i, resp in enumerate(ratios):
        top = sorted(table[resp].items(), key=lambda kv: -kv[1][0])[:3]
        needle = resp.split("_", 1)[1]
        view_study, rows = views[resp]
        for j, (name, (r2, p)) in enumerate(top):
            f = next(f for f in view_study["factors"] if f["name"] == name)
            ax = axes[i][j]
            ax.scatter([numeric(f, r[name]) for r in rows], [r[resp] for r in rows], s=14)
            ax.axhline(MEASURED_MM[needle] / MEASURED_MM["SB"], color="k", ls="--", lw=1, label="experiment")
            ax.set_xlabel(name + ("" if "range" in f else " (level index)"), fontsize=8)
            ax.set_ylabel(resp, fontsize=8)
            ax.set_title(f"R2-HSIC {r2:.2f}, p {p:.3f}", fontsize=8)
            if j == 0:
                ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def analyze(study, out, permutations=2000, top=3, root=None, regions=None):
    """The analysis of the study's complete points into OUT/analysis; with regions ([(factor, lo, hi)], study_region.py),
    of the points within them alone, the factors' ranges narrowed to them, into OUT/analysis_region_<factor>_<lo>_<hi>."""
    report_scatter = replica_scatter(study, root or os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")))
    records = read_points(study, out)
    folder = os.path.join(out, "analysis")
    if regions:
        study, records = region_study(study, records, regions)
        suffix, words = region_label(regions)
        folder = os.path.join(out, f"analysis_region_{suffix}")
    rows, incomplete = complete_rows(study, records)
    within = within_point_scatter(study, rows)
    # One run's noise: measured between each point's own runs where the study has replicas, else the paper report's.
    scatter = {r: within[r][0] for r in within} if within else report_scatter
    os.makedirs(folder, exist_ok=True)
    write_csv(os.path.join(folder, "points.csv"), rows)
    if len(rows) < 4:
        raise StudyError(f"{len(rows)} complete design points in {out}: the analysis needs at least 4")
    resp = responses(study)
    views = {r: response_view(study, rows, r) for r in resp}  # a factor acting within the lip clipped at each needle's lip
    table = {r: {name: (r2, p) for name, r2, p in hsic_indices(*views[r], r, permutations)} for r in resp}
    with open(os.path.join(folder, "hsic.csv.tmp"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["factor"] + [x for r in resp for x in (f"{r}_r2hsic", f"{r}_p")])
        for fac in study["factors"]:
            w.writerow([fac["name"]] + [f"{v:.6g}" if fac["name"] in table[r] else "" for r in resp for v in table[r].get(fac["name"], (0, 0))])
    os.replace(os.path.join(folder, "hsic.csv.tmp"), os.path.join(folder, "hsic.csv"))
    surrogates = []
    fitted = [x for x in resp if x.startswith("ratio_") or x == PLATEAU]  # the ratios and the plateau
    for r in fitted:
        names = [n for n, _ in sorted(table[r].items(), key=lambda kv: -kv[1][0])[:top]]
        surrogates.append(kriging_surrogate(*views[r], r, names, scatter.get(r)))
    chaos = [chaos_or_none(*views[r], r) for r in resp if r.startswith("ratio_")]
    chaos = [c for c in chaos if c]
    joint_factors = []
    for s_ in surrogates:
        joint_factors += [n for n in s_["factors"] if n not in joint_factors]
    own = {s_["response"].split("_", 1)[1]: s_["factors"] for s_ in surrogates if s_["response"].startswith("ratio_")}
    joint = joint_search(study, rows, joint_factors, scatter, own)
    nearest = min(rows, key=lambda r: r["calibrated_max_error_mm"])
    result = {"points_complete": len(rows), "points_incomplete": [{"point": p, "needles": s} for p, s in incomplete],
              "responses": resp, "hsic": {r: {n: {"r2_hsic": v[0], "p_value": v[1]} for n, v in table[r].items()} for r in resp},
              "replica_sd": scatter, "report_replica_sd": report_scatter,
              "within_point_sd": {r: {"sd": v[0], "dof": v[1]} for r, v in within.items()}, "surrogates": surrogates, "chaos": chaos, "joint": joint, "nearest_run_point": nearest, "measured_mm": MEASURED_MM}
    checks = held_out_checks(study, records, rows, fitted, scatter, permutations, top)
    for name, _, check in checks:
        result[name] = {k: v for k, v in check.items() if k != "rows"}
    with open(os.path.join(folder, "surrogate.json.tmp"), "w") as f:
        json.dump(result, f, indent=1)
    os.replace(os.path.join(folder, "surrogate.json.tmp"), os.path.join(folder, "surrogate.json"))
    md = [f"# Global sensitivity: {len(rows)} complete design points x {len(study['needles'])} needles", ""]
    if regions:
        md.extend([f"The region {words} of the study's box: its points alone, those ranges the factors' own (a factor acting within "
                   "the lip, narrowed to where it cannot act on a needle, drops out of that needle's surrogates); the held-out "
                   "checks predict their points in the region from the region's other points. Nothing is run.", ""])
    bonferroni = 0.05 / len(study["factors"])
    md.append(f"R2-HSIC index (p-value by permutation) of each factor for each response; bold: p < 0.05; and a dagger where "
              f"p < {bonferroni:.4f}, which holds for the {len(study['factors'])} factors of a response together (Bonferroni): with "
              f"{len(study['factors']) * len(resp)} tests, about {0.05 * len(study['factors']) * len(resp):.0f} fall below 0.05 by chance alone.")
    md.append("")
    md.append("| factor | " + " | ".join(resp) + " |")
    md.append("|---" * (len(resp) + 1) + "|")
    for fac in study["factors"]:
        cells = []
        for r in resp:
            if fac["name"] not in table[r]:
                cells.append("- (cannot act)")
                continue
            r2, p = table[r][fac["name"]]
            cell = f"{r2:.3f} ({p:.3f})"
            cells.append((f"**{cell}**" if p < 0.05 else cell) + (" †" if p < bonferroni else ""))
        md.append(f"| {fac['name']} | " + " | ".join(cells) + " |")
    md.append("")
    md.append("Kriging surrogates of the ratios to SB and of the plateau AMB - LMB on their three most influential factors (the others "
              "averaged out):")
    md.append("")
    if within:
        source = "the scatter between each point's own runs (its replicas), pooled over the points"
    elif scatter:
        source = f"{study['scatter_from']} and its replicas"
    md.append(f"(box min..max in brackets where the surrogate is not validated: its leave-one-out Q2 is below {MIN_Q2} and its leave-one-out "
              f"RMSE above {RMSE_OVER_SCATTER} times the noise of the values it predicts"
              + (f"; one run's noise is {source}, a point's mean of k runs carries it over sqrt(k), and the kriging takes it as the runs' noise"
                 if scatter else "") + ")")
    md.append("")
    md.append("| response | factors | LOO Q2 | LOO RMSE | one run's SD | the points' SD | observed min..max | box min..max | experiment |")
    md.append("|---|---|---|---|---|---|---|---|---|")
    for s in surrogates:
        experiment = (MEASURED_MM["AMB"] - MEASURED_MM["LMB"] if s["response"] == PLATEAU
                      else MEASURED_MM[s["response"].split("_", 1)[1]] / MEASURED_MM["SB"])
        md.append(f"| {s['response']} | {', '.join(s['factors'])} | {s['leave_one_out_q2']:.2f} | {s['leave_one_out_rmse']:.3f} | "
                  + (f"{s['replica_sd']:.3f} | {s['data_sd']:.3f}" if s["replica_sd"] else "- | -") + " | "
                  + f"{s['observed_min']:+.3f}..{s['observed_max']:+.3f} | "
                  + (f"{s['box_min']['value']:+.3f}..{s['box_max']['value']:+.3f}" if s["validated"] else
                     f"({s['box_min']['value']:+.3f}..{s['box_max']['value']:+.3f})") + reach_words(s)
                  + f" | {experiment:+.3f} |")
    md.append("")
    if within:
        md.extend(replica_lines(study, rows, within, report_scatter))
    md.append("Sparse additive polynomial chaos of each ratio over all the factors (each factor's polynomials to degree 2, or 1 where too few points, no interactions; LARS): first-order / total Sobol' indices of the "
              "factors with a total index of at least 0.05, and the chaos's leave-one-out Q2 (below about 0.5 the indices say little):")
    md.append("")
    for c in chaos:
        big = sorted(((n, v) for n, v in c["sobol"].items() if v[1] >= 0.05), key=lambda kv: -kv[1][1])
        md.append(f"- {c['response']} (degree {c['degree']}, Q2 {c['leave_one_out_q2']:.2f}, {c['terms']} terms): "
                  + (", ".join(f"{n} {v[0]:.2f} / {v[1]:.2f}" for n, v in big) if big else "no factor reaches 0.05")
                  + (f"; over the whole box {c['box_min']['value']:+.3f}..{c['box_max']['value']:+.3f}{reach_words(c)} (lowest at "
                     + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in c["box_min"]["at"].items()) + ")"
                     if c["validated"] else ""))
    md.append("")
    md.append("Calibrated on SB to first order (each needle's deflection = the measured SB's x its ratio to SB), against the experiment:")
    md.append("")
    md.append(f"- the run design point nearest the experiment: point {nearest['point']}, largest error {nearest['calibrated_max_error_mm']:.3f} mm ("
              + ", ".join(f"{n} {nearest[f'calibrated_error_{n}_mm']:+.3f}" for n in study["needles"] if n != "SB") + ")")
    md.append(("- " if joint["validated"] else "- NOT VALIDATED (a ratio's surrogate is not validated: its best point is no finding): ")
              + f"the surrogates' best point over {', '.join(joint['factors'])} (each ratio's kriging on its own factors above; LOO Q2 "
              + ", ".join(f"{n} {q:.2f}" for n, q in joint["leave_one_out_q2"].items()) + f"): largest error {joint['best_max_error_mm']:.3f} mm ("
              + ", ".join(f"{n} {e:+.3f}" for n, e in joint["best_calibrated_errors_mm"].items()) + ") at "
              + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in joint["best_at"].items())
              + (f"; EXTRAPOLATED: {joint['best_distance']['nearest_run']:.2f} from the nearest run point, the runs "
                 f"{joint['best_distance']['run_spacing']:.2f} apart (unit box)" if joint["best_distance"]["extrapolated"] else ""))
    if PLATEAU in resp:
        values = [r[PLATEAU] for r in rows]
        md.append(f"- AMB - LMB with SB calibrated, over the run points: {min(values):+.3f} to {max(values):+.3f} mm (the experiment: "
                  f"{MEASURED_MM['AMB'] - MEASURED_MM['LMB']:+.2f} +- 0.05 mm)")
    md.append(f"- two standard deviations of the experiment: {2 * POOLED_SD_MM:.2f} mm")
    md.append("")
    for name, heading, check in checks:
        md.extend(write_held_out(folder, name, heading, check, study, fitted))
    with open(os.path.join(folder, "hsic.md"), "w") as f:
        f.write("\n".join(md))
    plot_hsic(os.path.join(folder, "hsic.png"), study, table, resp)
    plot_scatter(os.path.join(folder, "ratio_scatter.png"), study, views, table)
    print("\n".join(md))
    return result


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.normpath(os.path.join(here, "..", ".."))
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--study", default=os.path.join(root, "data", "studies", "global_sensitivity.json"), help="the study file")
    p.add_argument("--out", required=True, help="the study folder (created; reruns resume)")
    p.add_argument("--batches", type=int, default=1, help="run batches 0..N-1 of the design (default 1)")
    p.add_argument("--batch", type=int, default=None,
                   help="run batch K alone, the others as they stand (the study's corner batch, say, beside a partial batch)")
    p.add_argument("--points", type=int, default=0,
                   help="run only the first N points of the last batch (a partial batch; a later run with more, or without, extends it)")
    p.add_argument("--jobs", type=int, default=2, help="worker processes of each sweep (default 2)")
    p.add_argument("--threads", type=int, default=0, help="threads a case (default: the cores divided among the jobs)")
    p.add_argument("--mpi", type=int, default=0, help="run each sweep on N MPI workers instead of --jobs")
    p.add_argument("--needle", default=os.path.join(root, "build", "apps", "needle"), help="the needle command")
    p.add_argument("--allow-other-code", action="store_true",
                   help="let a batch begun by another build of needle go on (needle sweep --allow-other-code; each case's summary names its build)")
    p.add_argument("--design-only", action="store_true", help="write the sweep files only")
    p.add_argument("--analyze-only", action="store_true", help="analyse the finished cases only")
    p.add_argument("--permutations", type=int, default=2000, help="permutations of the HSIC p-values (default 2000)")
    p.add_argument("--region", action="append", default=[], metavar="FACTOR=LO,HI",
                   help="with --analyze-only: analyse only the points whose FACTOR lies in [LO, HI], that range then the factor's own "
                        "(studies/sensitivity/study_region.py), into OUT/analysis_region_FACTOR_LO_HI; repeatable")
    args = p.parse_args(argv)
    try:
        study = read_study(args.study)
        if args.batches < 1:
            raise StudyError("--batches must be at least 1")
        if args.points < 0 or args.points > study["batch_points"]:
            raise StudyError(f"--points must be between 1 and the study's batch_points ({study['batch_points']})")
        if args.batch is not None and args.batch < 0:
            raise StudyError("--batch must be at least 0")
        regions = [parse_region(text, study) for text in args.region]
        if regions and not args.analyze_only:
            raise StudyError("--region analyses the stored points of a region: it goes with --analyze-only")
        if len({n for n, _, _ in regions}) != len(regions):
            raise StudyError("--region: each factor at most once")
        if not args.analyze_only:
            batches = [args.batch] if args.batch is not None else list(range(args.batches))
            for b in batches:
                for replica in replica_names(study):
                    path = write_batch(study, args.out, b, replica, args.points if args.points and b == batches[-1] else None)
                    if not args.design_only:
                        if not os.access(args.needle, os.X_OK):
                            raise StudyError(f"{args.needle}: no needle command (build it: bash scripts/build.sh needle)")
                        run_batch(args, path)
        if not args.design_only:
            analyze(study, args.out, args.permutations, regions=regions)
    except StudyError as e:
        print(f"global_sensitivity: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
