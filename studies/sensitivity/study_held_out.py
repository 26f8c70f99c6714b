"""The held-out checks of a study's surrogates: a study file's "held_out": {"from_batch": K}, its "corners"
(study_design.read_corners: the box's corners, predicted from the points below "fitted_on_points_below") and its
"points_held_out": {"points": [a, b]} (the points a..b-1, predicted from every other complete point: a round for the
surrogates as refitted after the earlier checks).

A surrogate's leave-one-out Q2 is computed on the points its form was chosen on. The held-out check asks the harder
question: the analysis's own procedure (each response's HSIC screen, its most influential factors, the kriging with the
runs' noise, the study's trend) is fitted on the points of batches 0..K-1 only, and predicts the points of batches K
and after, with a standard deviation (the kriging's own, plus the noise of a point's mean). The predictions are written
from the design alone, so they can be stored before those points are run; as their runs complete, the analysis adds
the observed means and judges the predictions by the same rule as leave-one-out (Q2 over the held-out points >= MIN_Q2,
or their RMSE within RMSE_OVER_SCATTER times the noise of the means).
"""
import csv
import math
import os

from study_runs import response_view, within_point_scatter
from study_surrogates import MIN_Q2, RMSE_OVER_SCATTER, data_sd, fit_kriging, hsic_indices, surrogate_validated
from study_design import corner_batch, unit_coordinate


def corner_points(study, records):
    """The design points of the corner batch, whether run or not (none without "corners")."""
    batch = corner_batch(study)
    if batch is None:
        return []
    n = study["batch_points"]
    return sorted(p for p in records if batch * n <= p < (batch + 1) * n)


def held_out_points(study, records):
    """The design points of the held-out batches (those from held_out.from_batch on, the corners left to their own
    check), whether run or not."""
    first = study["held_out"]["from_batch"] * study["batch_points"]
    corners = set(corner_points(study, records))
    return sorted(p for p in records if p >= first and p not in corners)


def held_out_checks(study, records, rows, responses, scatter, permutations=2000, top=3):
    """Each held-out check the study declares: [(name, heading, check)], "held_out" (batch K on, fitted on the batches
    before), "corners_held_out" (the corner batch, fitted on the complete points below fitted_on_points_below) and
    "points_held_out" (points a..b-1, fitted on every other complete point); the name is the check's key in
    surrogate.json and its table's file name, the heading its section's in hsic.md, each written where the check is
    declared."""
    def check(fitted, points):
        return held_out_check(study, records, rows, responses, scatter, permutations, top, fitted, points)

    checks = []
    if study.get("held_out"):
        batch = study["held_out"]["from_batch"]
        first = batch * study["batch_points"]
        c = check(lambda p: p < first, held_out_points(study, records))
        checks.append(("held_out", f"the surrogates fitted on batches 0..{batch - 1} ({c['fitted_points']} points) predict the "
                                   f"{len(c['points'])} points of batch {batch} on (the corners apart)", c))
    if study.get("corners"):
        spec = study["corners"]
        below = spec["fitted_on_points_below"]
        corners = set(corner_points(study, records))
        c = check(lambda p: p < below and p not in corners, sorted(corners))
        checks.append(("corners_held_out", f"the surrogates fitted on the {c['fitted_points']} complete points below point {below} "
                                           f"predict the {len(c['points'])} corners of batch {spec['batch']} ({'half of ' if spec.get('half_fraction') else ''}"
                                           f"the box's corners in {', '.join(spec['factors'])}; the other factors at their middle)", c))
    if study.get("points_held_out"):
        first, end = study["points_held_out"]["points"]
        c = check(lambda p: not first <= p < end, [p for p in sorted(records) if first <= p < end])
        checks.append(("points_held_out", f"the surrogates fitted on every other complete point ({c['fitted_points']} points) predict "
                                          f"points {first}..{end - 1} ({len(c['points'])} in the design so far)", c))
    return checks


def predict(study, fit_rows, response, noise_sd, points_values, permutations, top):
    """The procedure fitted on fit_rows for one response, and its (mean, sd) at each of points_values ({key: value})."""
    import openturns as ot
    view_study, view_rows = response_view(study, fit_rows, response)
    ranked = sorted(hsic_indices(view_study, view_rows, response, permutations), key=lambda t: -t[1])
    names = [name for name, _, _ in ranked[:top]]
    _, factors, q2, rmse, result = fit_kriging(view_study, view_rows, response, names, noise_sd)
    predictions = []
    for values in points_values:
        x = []
        for f in factors:
            value = values[f["key"]]
            if f.get("acts_within_lip"):  # clipped at the lip as the fitted points were (the needle's lip: its geometry)
                value = min(max(value, f["range"][0]), f["range"][1])
            x.append(unit_coordinate(f, value))
        mean = result.getConditionalMean(ot.Point(x))[0]
        variance = max(0.0, result.getConditionalMarginalVariance(ot.Point(x)))  # the surrogate's own, without the runs' noise
        predictions.append((mean, variance))
    return names, q2, rmse, predictions


def held_out_check(study, records, rows, responses, scatter, permutations, top, fitted, points):
    """{"fitted_points", "points", "responses": {response: {...}}, "rows": [...]}: each response's procedure fitted on
    the complete rows whose point `fitted` accepts, its predictions at `points`, the observed means where a point is
    complete, and the verdict. The noise (the kriging's nugget, the sd of a prediction, the bar) is the fitted points'
    own where the study has replicas, else `scatter`."""
    fit_rows = [r for r in rows if fitted(r["point"])]
    observed = {r["point"]: r for r in rows if r["point"] in set(points)}
    # The runs' noise as the fitted points alone measure it (their replicas), so that nothing of the held-out points
    # enters the predictions; without replicas, the analysis's (the paper report's).
    within = within_point_scatter(study, fit_rows)
    scatter = {r: v[0] for r, v in within.items()} if within else scatter
    runs_per_point = 1 + len(study.get("replicas", []))
    table = [{"point": p, **{f["name"]: records[p]["values"][f["key"]] for f in study["factors"]},
              "runs": observed[p]["runs"] if p in observed else 0} for p in points]
    summary = {}
    for response in responses:
        noise = scatter.get(response)
        names, q2, rmse, predictions = predict(study, fit_rows, response, noise, [records[p]["values"] for p in points], permutations, top)
        errors, within = [], 0
        for row, p, (mean, variance) in zip(table, points, predictions):
            runs = observed[p]["runs"] if p in observed else runs_per_point
            sd = math.sqrt(variance + (noise or 0.0) ** 2 / runs)  # the surrogate's own, and the noise of a mean of `runs`
            row[f"{response}_predicted"] = mean
            row[f"{response}_sd"] = sd
            row[f"{response}_observed"] = observed[p][response] if p in observed else None
            if p in observed:
                errors.append(observed[p][response] - mean)
                within += abs(errors[-1]) <= 2.0 * sd
        entry = {"factors": names, "fitted_leave_one_out_q2": q2, "fitted_leave_one_out_rmse": rmse, "observed_points": len(errors)}
        if errors:
            values = [observed[p][response] for p in points if p in observed]
            mean_obs = sum(values) / len(values)
            spread = sum((v - mean_obs) ** 2 for v in values) / len(values)
            held_rmse = math.sqrt(sum(e * e for e in errors) / len(errors))
            held_q2 = 1.0 - held_rmse ** 2 / spread if spread > 0 and len(errors) >= 3 else float("nan")
            bar_noise = data_sd([observed[p] for p in points if p in observed], noise)
            entry.update({"rmse": held_rmse, "q2": held_q2, "bias": sum(errors) / len(errors), "within_two_sd": within,
                          "means_noise": bar_noise, "validated": surrogate_validated(held_q2 if held_q2 == held_q2 else -1.0, held_rmse, bar_noise)})
        summary[response] = entry
    return {"fitted_points": len(fit_rows), "top": top, "points": points, "responses": summary, "rows": table}


def write_held_out(folder, name, heading, check, study, responses):
    """NAME.csv (one row a held-out point: its factors, each response's prediction, sd and observed mean) and the
    Markdown lines of the check under its heading (held_out_checks)."""
    columns = ["point"] + [f["name"] for f in study["factors"]] + ["runs"] + [
        f"{r}_{k}" for r in responses for k in ("predicted", "sd", "observed")]
    path = os.path.join(folder, f"{name}.csv")
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for row in check["rows"]:
            w.writerow(["" if row.get(c) is None else (f"{row[c]:.6g}" if isinstance(row[c], float) else row[c]) for c in columns])
    os.replace(path + ".tmp", path)
    md = [f"## Held out: {heading}", ""]
    md += [
          f"Each response's procedure as above (its {check['top']} most influential factors by HSIC, "
          f"the kriging with a {study.get('kriging_trend', 'constant')} trend and the runs' noise), fitted without the held-out points; "
          f"validated by the leave-one-out rule (Q2 over the held-out points >= {MIN_Q2}, or their RMSE within {RMSE_OVER_SCATTER} times "
          "the noise of their means). The predictions come from the design alone "
          f"({name}.csv), so they stand before the runs.", "",
          "| response | factors | fitted LOO Q2 | held-out points run | RMSE | bar | Q2 | mean error | within 2 sd | validated |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for r in responses:
        e = check["responses"][r]
        if e["observed_points"]:
            md.append(f"| {r} | {', '.join(e['factors'])} | {e['fitted_leave_one_out_q2']:.2f} | {e['observed_points']} | {e['rmse']:.3f} | "
                      + (f"{RMSE_OVER_SCATTER * e['means_noise']:.3f}" if e["means_noise"] else "-") + f" | {e['q2']:.2f} | {e['bias']:+.3f} | {e['within_two_sd']} of {e['observed_points']} | "
                      + ("yes" if e["validated"] else "no") + " |")
        else:
            md.append(f"| {r} | {', '.join(e['factors'])} | {e['fitted_leave_one_out_q2']:.2f} | 0 | - | - | - | - | - | not yet run |")
    md.append("")
    return md
