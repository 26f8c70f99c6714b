"""The global sensitivity study's runs (studies/sensitivity/global_sensitivity.py): the sweeps' case records read
back as design points, the responses of each (the deflections, the ratios to SB, the plateau), their means over a
point's replicas and the scatter between them, and the paper report's replicas' scatter."""
import json
import math
import os
import re
import statistics

from study_design import StudyError, batch_cases, batch_folder, replica_names

MEASURED_MM = {"SB": -1.14, "LMB": 0.15, "AMB": 0.24, "HMB": 1.71}
POOLED_SD_MM = 0.105  # the paper's ANOVA: F = 1220.4 with 3 and 36 degrees of freedom
# The measured plateau: AMB - LMB = +0.09 +- 0.05 mm (p = 0.457). Ours, with SB calibrated: -1.14 mm x (ratio_AMB - ratio_LMB).
PLATEAU = "calibrated_AMB_minus_LMB_mm"


def case_records(cases_dir):
    """(case folder, case.json) of every case a sweep has recorded in cases_dir, in case order."""
    if not os.path.isdir(cases_dir):
        return
    for name in sorted(os.listdir(cases_dir)):
        path = os.path.join(cases_dir, name, "case.json")
        if os.path.exists(path):
            with open(path) as f:
                yield os.path.join(cases_dir, name), json.load(f)


def read_points(study, out):
    """Every design point's runs, from the batches' case records: {point: {"values": {key: value}, "runs": {replica:
    {needle: entry}}}}, the plain run under the replica "" (replica_names)."""
    records = {}
    present = sorted(int(m.group(1)) for m in (re.fullmatch(r"batch_(\d+)", name) for name in (os.listdir(out) if os.path.isdir(out) else []))
                     if m and os.path.exists(os.path.join(batch_folder(out, int(m.group(1))), "sweep.json")))
    for batch in present:  # a batch run alone (--batch) may follow a gap
        for point, needle, values in batch_cases(study, batch):
            records.setdefault(point, {"values": values, "runs": {name: {} for name in replica_names(study)}})
        for replica in replica_names(study):
            for case_dir, record in case_records(os.path.join(batch_folder(out, batch, replica), "sweep", "cases")):
                parts = record.get("label", "").split()
                if len(parts) != 3 or parts[0] != "point":
                    continue
                point, needle = int(parts[1]), parts[2]
                entry = {"status": record.get("status"), "reason": record.get("reason", ""),
                         "deflection_mm": record.get("deflection_mm"), "groove_fill": record.get("groove_fill"),
                         "runtime_s": record.get("runtime_s"), "floor_contact": None}
                summary = os.path.join(case_dir, "run", "summary.json")
                if os.path.exists(summary):
                    with open(summary) as f:
                        s = json.load(f)
                    entry["floor_contact"] = (s.get("groove") or {}).get("floor_contact_fraction")
                    entry["lip_thickness_mm"] = (s.get("lip_release") or {}).get("lip_thickness_mm", 0.0)  # none: no lip
                records[point]["runs"][replica][needle] = entry
    return records


def responses(study):
    names = [f"delta_{n}_mm" for n in study["needles"]]
    names += [f"ratio_{n}" for n in study["needles"] if n != "SB"]
    if "LMB" in study["needles"] and "AMB" in study["needles"]:
        names.append(PLATEAU)
    return names


def run_responses(study, needles):
    """The responses of one complete run of a point (every needle finished): {response: value}."""
    sb = needles["SB"]["deflection_mm"]
    values = {f"delta_{n}_mm": needles[n]["deflection_mm"] for n in study["needles"]}
    values.update({f"ratio_{n}": needles[n]["deflection_mm"] / sb for n in study["needles"] if n != "SB"})
    if "LMB" in needles and "AMB" in needles:
        values[PLATEAU] = MEASURED_MM["SB"] * (values["ratio_AMB"] - values["ratio_LMB"])
    return values


def mean_of(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else None


def run_column(response, replica):
    """The column of one run's response beside a point's mean: "ratio_LMB@y0.1", "ratio_LMB@plain" for the plain run."""
    return f"{response}@{replica or 'plain'}"


def point_runs(study, row, response):
    """The response of each complete run of a row's point (one value without replicas' columns)."""
    return [row[run_column(response, name)] for name in replica_names(study) if row.get(run_column(response, name)) is not None]


def complete_rows(study, records):
    """One row a point with at least one complete run (every needle finished): its factors and, for each response, the
    mean over its complete runs (the plain one and the replicas'); "runs" counts them, and with replicas each run's
    responses are kept beside ("ratio_LMB@y0.1"; "@plain" for the plain run). A point without a complete run is listed
    as incomplete with its runs' statuses."""
    rows, incomplete = [], []
    names = replica_names(study)
    for point in sorted(records):
        rec = records[point]
        complete = [name for name in names
                    if all(n in rec["runs"][name] and rec["runs"][name][n]["status"] == "finished"
                           and rec["runs"][name][n]["deflection_mm"] is not None for n in study["needles"])]
        if not complete:
            incomplete.append((point, {n: (rec["runs"][""][n]["status"], rec["runs"][""][n]["reason"]) if n in rec["runs"][""] else ("pending", "")
                                       for n in study["needles"]}))
            continue
        row = {"point": point, "runs": len(complete)}
        for f in study["factors"]:
            row[f["name"]] = rec["values"][f["key"]]
        per_run = {name: run_responses(study, rec["runs"][name]) for name in complete}
        for r in responses(study):
            row[r] = mean_of(per_run[name][r] for name in complete)
        for n in study["needles"]:
            for field, column in (("groove_fill", "groove_fill"), ("floor_contact", "floor_contact"), ("runtime_s", "runtime")):
                suffix = "_s" if field == "runtime_s" else ""
                row[f"{column}_{n}{suffix}"] = mean_of(rec["runs"][name][n][field] for name in complete)
        if any(f.get("acts_within_lip") for f in study["factors"]):
            for n in study["needles"]:
                thickness = [rec["runs"][name][n].get("lip_thickness_mm") for name in complete]
                if any(t is None for t in thickness):
                    raise StudyError(f"point {point} {n}: a factor acts within the lip, but the run's summary.json is missing")
                row[f"lip_thickness_{n}_mm"] = max(thickness)
        errors = calibrated_errors({n: row[f"ratio_{n}"] for n in study["needles"] if n != "SB"})
        for n, e in errors.items():
            row[f"calibrated_error_{n}_mm"] = e
        row["calibrated_max_error_mm"] = max(abs(e) for e in errors.values())
        if len(names) > 1:
            for name in names:
                for r in responses(study):
                    row[run_column(r, name)] = per_run[name][r] if name in per_run else None
        rows.append(row)
    return rows, incomplete


def response_needles(study, response):
    """The needles a response is made of: a deflection its needle's, a ratio its needle's and SB's, the plateau LMB's,
    AMB's and SB's."""
    if response.startswith("delta_"):
        return [response.split("_")[1]]
    if response.startswith("ratio_"):
        return [response.split("_", 1)[1], "SB"]
    if response == PLATEAU:
        return ["LMB", "AMB", "SB"]
    return list(study["needles"])


def response_view(study, rows, response):
    """The study and its rows as one response sees them: a factor that acts within the lip (a depth below tip point A)
    acts on a needle only up to that needle's lip thickness; beyond it the whole lip is crushed and the run is the same
    to the last digit. So for this response the factor is clipped at the thickest lip of the response's needles (each
    row's own, from its runs' summaries), its range with it; where that leaves under 5 % of its range (SB has no lip,
    LMB's lip is 0.21 mm), the factor cannot act on the response and is left out. Without such a factor, the study and
    rows as they are."""
    clipped = [f for f in study["factors"] if f.get("acts_within_lip")]
    if not clipped:
        return study, rows
    needles = response_needles(study, response)
    factors, view_rows = [], [dict(r) for r in rows]
    for f in study["factors"]:
        if not f.get("acts_within_lip"):
            factors.append(f)
            continue
        lo, hi = f["range"]
        limits = [max(r[f"lip_thickness_{n}_mm"] for n in needles) for r in rows]
        top = min(hi, max(limits))
        if top - lo < 0.05 * (hi - lo):
            continue
        factors.append(dict(f, range=[lo, top]))
        for r, limit in zip(view_rows, limits):
            r[f["name"]] = max(lo, min(r[f["name"]], limit))
    return dict(study, factors=factors), view_rows


def within_point_scatter(study, rows):
    """{response: (standard deviation, degrees of freedom)}: the scatter between a point's runs (the plain one and its
    replicas), pooled over the points with two runs or more. {} for a study without replicas."""
    if len(replica_names(study)) < 2:
        return {}
    out = {}
    for r in responses(study):
        squares, dof = 0.0, 0
        for row in rows:
            values = point_runs(study, row, r)
            if len(values) >= 2:
                m = sum(values) / len(values)
                squares += sum((v - m) ** 2 for v in values)
                dof += len(values) - 1
        if dof >= 2:
            out[r] = (math.sqrt(squares / dof), dof)
    return out


def replica_scatter(study, root):
    """{response: its standard deviation over a paper report and its replicas}: the run-to-run scatter of each response
    (the same model, the lattice shifted, other rounding), from the study's 'scatter_from' (a `needle paper` results.json
    whose 'replicas' list the others; paths relative to the repository). {} without it."""
    if "scatter_from" not in study:
        return {}
    main = os.path.join(root, study["scatter_from"])
    try:
        with open(main) as f:
            reports = [json.load(f)]
        for replica in reports[0].get("replicas", []):
            with open(os.path.join(root, replica["results"])) as f:
                reports.append(json.load(f))
    except (OSError, json.JSONDecodeError, KeyError, TypeError) as e:
        raise StudyError(f"scatter_from {study['scatter_from']}: {e}")
    samples = {}
    for report in reports:
        needles = report.get("needles", {})
        delta = {n: needles[n]["deflection_mm"] for n in study["needles"]
                 if n in needles and needles[n].get("status") == "finished" and needles[n].get("deflection_mm") is not None}
        if len(delta) != len(study["needles"]):
            continue  # a report without every needle of the study says nothing of the ratios
        values = {f"delta_{n}_mm": d for n, d in delta.items()}
        values.update({f"ratio_{n}": d / delta["SB"] for n, d in delta.items() if n != "SB"})
        if "LMB" in delta and "AMB" in delta:
            values[PLATEAU] = MEASURED_MM["SB"] * (values["ratio_AMB"] - values["ratio_LMB"])
        for k, v in values.items():
            samples.setdefault(k, []).append(v)
    if not samples or min(len(v) for v in samples.values()) < 2:
        raise StudyError(f"scatter_from {study['scatter_from']}: fewer than two reports with every needle of the study")
    return {k: statistics.stdev(v) for k, v in samples.items()}


def calibrated_errors(ratios):
    """Each multi-bevel needle's deflection with SB calibrated to the experiment, to first order (delta_X = delta_SB,measured
    x ratio_X), less the measured one: {needle: error_mm}."""
    return {n: MEASURED_MM["SB"] * r - MEASURED_MM[n] for n, r in ratios.items()}
