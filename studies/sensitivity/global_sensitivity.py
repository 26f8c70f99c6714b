#!/usr/bin/python3
"""The global sensitivity study of the paper's unknowns (issue 47; docs/notebook/sensitivity_study.md).

Every unknown of the study file (data/studies/global_sensitivity.json) is varied at once over its range on a Sobol'
low-discrepancy design (OpenTURNS). Each design point is run on the four paper needles at 30 mm through
`needle sweep` (worker processes, or MPI with --mpi N), one sweep per batch of points, so batch k+1 extends the study
without moving batches 0..k. The analysis ranks the factors by their HSIC indices (OpenTURNS, with permutation
p-values) for each response (the four deflections and each multi-bevel needle's ratio to SB, which a calibration of E
on SB leaves as the prediction: delta_X ~ -1.14 mm * ratio) and fits a kriging surrogate of the ratios on the factors
that matter, with its leave-one-out error, to find how far the admissible box can move them.

    /usr/bin/python3 studies/sensitivity/global_sensitivity.py --out study --batches 2 --jobs 2   # design, run, analyse
    /usr/bin/python3 studies/sensitivity/global_sensitivity.py --out study --analyze-only         # the tables again

Writes into --out: batch_K/sweep.json (the sweep file of batch K) and batch_K/sweep/ (its sweep folder), and
analysis/: points.csv (one row a design point: the factors, each needle's deflection, groove fill and floor contact,
the ratios), hsic.csv and hsic.md (R2-HSIC index and p-value of every factor for every response), surrogate.json
(the kriging surrogates, their leave-one-out Q2 and the box's reach), hsic.png and ratio_scatter.png.
Python, not C++: the statistics are OpenTURNS's (python3-openturns), and the runs are the `needle` command's.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys

MEASURED_MM = {"SB": -1.14, "LMB": 0.15, "AMB": 0.24, "HMB": 1.71}
POOLED_SD_MM = 0.105  # the paper's ANOVA: F = 1220.4 with 3 and 36 degrees of freedom
# The measured plateau: AMB - LMB = +0.09 +- 0.05 mm (p = 0.457). Ours, with SB calibrated: -1.14 mm x (ratio_AMB - ratio_LMB).
PLATEAU = "calibrated_AMB_minus_LMB_mm"
MIN_Q2 = 0.5  # below it a surrogate does not predict left-out points well enough for its extremes to be claimed
# ... unless the runs themselves scatter: a surrogate that misses a left-out point by no more than this many of the
# replicas' standard deviations predicts it about as well as the same run on a shifted lattice would.
RMSE_OVER_SCATTER = 1.5


class StudyError(Exception):
    pass


def read_study(path):
    try:
        with open(path) as f:
            study = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        raise StudyError(f"{path}: {e}")
    for key in ("needles", "factors", "batch_points"):
        if key not in study:
            raise StudyError(f"{path}: missing '{key}'")
    if "SB" not in study["needles"]:
        raise StudyError(f"{path}: the needles must include SB (the ratios are to SB)")
    names = set()
    for f in study["factors"]:
        if not isinstance(f, dict) or "name" not in f or "key" not in f:
            raise StudyError(f"{path}: each factor needs a 'name' and a scene 'key'")
        if f["name"] in names:
            raise StudyError(f"{path}: factor '{f['name']}' appears twice")
        names.add(f["name"])
        if ("range" in f) == ("levels" in f):
            raise StudyError(f"{path}: factor '{f['name']}' needs either 'range' [lo, hi] or 'levels' [...]")
        if "range" in f and not (len(f["range"]) == 2 and f["range"][0] < f["range"][1]):
            raise StudyError(f"{path}: factor '{f['name']}': 'range' must be [lo, hi] with lo < hi")
        if "levels" in f and len(f["levels"]) < 2:
            raise StudyError(f"{path}: factor '{f['name']}': give at least two levels")
    if not (isinstance(study["batch_points"], int) and study["batch_points"] >= 2):
        raise StudyError(f"{path}: 'batch_points' must be an integer of at least 2")
    return study


def unit_design(dimension, count):
    """The first `count` points of the Sobol' sequence in [0, 1)^dimension (the same for every run and machine)."""
    import openturns as ot
    sample = ot.SobolSequence(dimension).generate(count)
    return [[float(v) for v in row] for row in sample]


def factor_value(factor, u):
    """The factor's value at the unit coordinate u: a range is mapped linearly, levels take equal shares of [0, 1)."""
    if "range" in factor:
        lo, hi = factor["range"]
        return float(f"{lo + u * (hi - lo):.6g}")
    levels = factor["levels"]
    return levels[min(int(u * len(levels)), len(levels) - 1)]


def numeric(factor, value):
    """A factor's value as a number for the statistics: a level by its index."""
    if "range" in factor:
        return float(value)
    return float(factor["levels"].index(value))


def unit_coordinate(factor, value):
    """A factor's value scaled to [0, 1]: over its range, or its level's index over the levels."""
    if "range" in factor:
        lo, hi = factor["range"]
        return (float(value) - lo) / (hi - lo)
    return factor["levels"].index(value) / (len(factor["levels"]) - 1)


def value_at_unit(factor, u):
    if "range" in factor:
        lo, hi = factor["range"]
        return lo + u * (hi - lo)
    return factor["levels"][int(round(u * (len(factor["levels"]) - 1)))]


def batch_cases(study, batch):
    """The design points of one batch, each run on every needle: [(point index, needle, {key: value})]."""
    n = study["batch_points"]
    points = unit_design(len(study["factors"]), (batch + 1) * n)[batch * n:]
    cases = []
    for k, u in enumerate(points):
        point = batch * n + k
        values = {f["key"]: factor_value(f, uk) for f, uk in zip(study["factors"], u)}
        for needle in study["needles"]:
            cases.append((point, needle, values))
    return cases


def sweep_file(study, batch):
    cases = []
    for point, needle, values in batch_cases(study, batch):
        case = {"label": f"point {point:03d} {needle}", "needle.preset": needle}
        case.update(values)
        cases.append(case)
    sweep = {"design": {"cases": cases}}
    if study.get("model"):
        sweep["model"] = study["model"]
    if study.get("set"):
        sweep["set"] = study["set"]
    return sweep


def write_sweep_file(path, sweep):
    """Writes a study's sweep file whole, or accepts the same one already there (a rerun); StudyError for another."""
    text = json.dumps(sweep, indent=1) + "\n"
    if os.path.exists(path):
        with open(path) as f:
            if f.read() != text:
                raise StudyError(f"{path} holds another design (the study changed?): give a new --out")
    else:
        with open(path + ".tmp", "w") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
    return path


def case_records(cases_dir):
    """(case folder, case.json) of every case a sweep has recorded in cases_dir, in case order."""
    if not os.path.isdir(cases_dir):
        return
    for name in sorted(os.listdir(cases_dir)):
        path = os.path.join(cases_dir, name, "case.json")
        if os.path.exists(path):
            with open(path) as f:
                yield os.path.join(cases_dir, name), json.load(f)


def write_batch(study, out, batch):
    folder = os.path.join(out, f"batch_{batch}")
    os.makedirs(folder, exist_ok=True)
    return write_sweep_file(os.path.join(folder, "sweep.json"), sweep_file(study, batch))


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
    print("global_sensitivity:", " ".join(command), flush=True)
    status = subprocess.call(command)
    if status == 3:  # the table is written; some cases stopped or failed: the analysis leaves their points out
        print(f"global_sensitivity: some cases of {sweep_path} did not finish; their points are left out", flush=True)
    elif status != 0:
        raise StudyError(f"needle sweep exited {status} for {sweep_path}")


# ---------------------------------------------------------------------------------------------------------------
# Analysis


def read_points(study, out):
    """Every finished design point (all its needles finished), from the batches' case records."""
    records = {}
    batch = 0
    while os.path.exists(os.path.join(out, f"batch_{batch}", "sweep.json")):
        cases_dir = os.path.join(out, f"batch_{batch}", "sweep", "cases")
        for point, needle, values in batch_cases(study, batch):
            records.setdefault(point, {"values": values, "needles": {}})
        for case_dir, record in case_records(cases_dir):
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
            records[point]["needles"][needle] = entry
        batch += 1
    return records


def responses(study):
    names = [f"delta_{n}_mm" for n in study["needles"]]
    names += [f"ratio_{n}" for n in study["needles"] if n != "SB"]
    if "LMB" in study["needles"] and "AMB" in study["needles"]:
        names.append(PLATEAU)
    return names


def complete_rows(study, records):
    rows, incomplete = [], []
    for point in sorted(records):
        rec = records[point]
        needles = rec["needles"]
        ok = all(n in needles and needles[n]["status"] == "finished" and needles[n]["deflection_mm"] is not None
                 for n in study["needles"])
        if not ok:
            incomplete.append((point, {n: (needles[n]["status"], needles[n]["reason"]) if n in needles else ("pending", "")
                                       for n in study["needles"]}))
            continue
        row = {"point": point}
        for f in study["factors"]:
            row[f["name"]] = rec["values"][f["key"]]
        sb = needles["SB"]["deflection_mm"]
        for n in study["needles"]:
            row[f"delta_{n}_mm"] = needles[n]["deflection_mm"]
            row[f"groove_fill_{n}"] = needles[n]["groove_fill"]
            row[f"floor_contact_{n}"] = needles[n]["floor_contact"]
            row[f"runtime_{n}_s"] = needles[n]["runtime_s"]
            if n != "SB":
                row[f"ratio_{n}"] = needles[n]["deflection_mm"] / sb
        errors = calibrated_errors({n: row[f"ratio_{n}"] for n in study["needles"] if n != "SB"})
        for n, e in errors.items():
            row[f"calibrated_error_{n}_mm"] = e
        row["calibrated_max_error_mm"] = max(abs(e) for e in errors.values())
        if "LMB" in needles and "AMB" in needles:
            row[PLATEAU] = MEASURED_MM["SB"] * (row["ratio_AMB"] - row["ratio_LMB"])
        rows.append(row)
    return rows, incomplete


def hsic_indices(study, rows, response, permutations=2000, seed=1):
    """R2-HSIC index and permutation p-value of every factor for one response (Gaussian kernels, each scaled by its
    sample's standard deviation)."""
    import openturns as ot
    ot.RandomGenerator.SetSeed(seed)
    factors = study["factors"]
    x = ot.Sample([[numeric(f, r[f["name"]]) for f in factors] for r in rows])
    y = ot.Sample([[r[response]] for r in rows])
    covariances = []
    for j in range(x.getDimension()):
        sd = x.getMarginal(j).computeStandardDeviation()[0]
        covariances.append(ot.SquaredExponential([sd if sd > 0 else 1.0]))
    sd_y = y.computeStandardDeviation()[0]
    covariances.append(ot.SquaredExponential([sd_y if sd_y > 0 else 1.0]))
    estimator = ot.HSICEstimatorGlobalSensitivity(covariances, x, y, ot.HSICUStat())
    estimator.setPermutationSize(permutations)
    r2 = estimator.getR2HSICIndices()
    p = estimator.getPValuesPermutation()
    return [(factors[j]["name"], float(r2[j]), float(p[j])) for j in range(len(factors))]


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


def surrogate_validated(q2, rmse, scatter_sd):
    """A surrogate is validated when it predicts left-out points (Q2 >= MIN_Q2), or misses them by no more than
    RMSE_OVER_SCATTER of the runs' own scatter (then the response's spread over the box is mostly that scatter)."""
    return q2 >= MIN_Q2 or (scatter_sd is not None and scatter_sd > 0 and rmse <= RMSE_OVER_SCATTER * scatter_sd)


def fit_kriging(study, rows, response, factor_names, noise_sd=None):
    """A kriging surrogate of the response on the named factors (constant trend, squared-exponential ARD, each factor
    scaled to [0, 1] over its range) and its leave-one-out Q2 and RMSE: (model, factors, q2, rmse). With noise_sd (the
    runs' own scatter), each run is taken as the response plus that noise: the surrogate smooths rather than
    interpolates, and its extremes are those of the response, not of one run's rounding."""
    import openturns as ot
    ot.Log.Show(ot.Log.NONE)  # OpenTURNS warns each time it narrows the correlation lengths' bounds to the data
    factors = [f for f in study["factors"] if f["name"] in factor_names]
    x = ot.Sample([[unit_coordinate(f, r[f["name"]]) for f in factors] for r in rows])
    y = ot.Sample([[r[response]] for r in rows])
    dim = len(factors)

    def fit(xs, ys):
        basis = ot.ConstantBasisFactory(dim).build()
        algo = ot.KrigingAlgorithm(xs, ys, ot.SquaredExponential([0.5] * dim, [1.0]), basis)
        algo.setOptimizationBounds(ot.Interval([0.05] * dim, [10.0] * dim))
        if noise_sd:
            algo.setNoise([noise_sd * noise_sd] * xs.getSize())
        algo.run()
        return algo.getResult().getMetaModel()

    n = x.getSize()
    errors = []
    for k in range(n):
        keep = [i for i in range(n) if i != k]
        errors.append(fit(x[keep], y[keep])(x[k])[0] - y[k][0])
    mean = y.computeMean()[0]
    variance = sum((y[i][0] - mean) ** 2 for i in range(n)) / n
    press = sum(e * e for e in errors) / n
    q2 = 1.0 - press / variance if variance > 0 else float("nan")
    return fit(x, y), factors, q2, math.sqrt(press)


def pce_sobol(study, rows, response, degree=2):
    """A sparse additive polynomial chaos of the response over every factor (Legendre polynomials of each factor scaled to
    [0, 1] up to `degree`, no interaction terms, the terms chosen by LARS with corrected leave-one-out), its leave-one-out Q2 (refitted without
    each point), and the first-order and total Sobol' indices it gives: {factor: (first, total)}."""
    import openturns as ot
    ot.Log.Show(ot.Log.NONE)
    factors = study["factors"]
    dim = len(factors)
    x = ot.Sample([[unit_coordinate(f, r[f["name"]]) for f in factors] for r in rows])
    y = ot.Sample([[r[response]] for r in rows])
    # A range is uniform on [0, 1] (Legendre polynomials); a factor of L levels takes each of its L points with equal
    # weight (its own orthogonal polynomials), and no polynomial of degree L or more, which its points cannot tell from
    # the lower ones: the enumeration's weight L - 1 ... is 2 for two levels, so a degree-2 chaos gives it degree 1.
    marginals, families, weights = [], [], []
    for f in factors:
        if "range" in f:
            marginals.append(ot.Uniform(0.0, 1.0))
            families.append(ot.LegendreFactory())
            weights.append(1.0)
        else:
            count = len(f["levels"])
            points = ot.UserDefined([[k / (count - 1)] for k in range(count)])
            marginals.append(points)
            families.append(ot.StandardDistributionPolynomialFactory(ot.AdaptiveStieltjesAlgorithm(points)))
            weights.append(degree / (count - 1) if count - 1 < degree else 1.0)
    distribution = ot.ComposedDistribution(marginals)
    # Hyperbolic truncation (q = 0.5): each factor's own polynomials up to the degree, no products of two factors. With a
    # few dozen points in sixteen dimensions the products alias the main effects, and LARS would pick aliases.
    basis = ot.OrthogonalProductPolynomialFactory(families, ot.HyperbolicAnisotropicEnumerateFunction(weights, 0.5))
    size = basis.getEnumerateFunction().getStrataCumulatedCardinal(degree)

    def fit(xs, ys):
        algo = ot.FunctionalChaosAlgorithm(xs, ys, distribution, ot.FixedStrategy(basis, size),
                                           ot.LeastSquaresStrategy(ot.LeastSquaresMetaModelSelectionFactory(ot.LARS(), ot.CorrectedLeaveOneOut())))
        algo.run()
        return algo.getResult()

    n = x.getSize()
    errors = []
    for k in range(n):
        keep = [i for i in range(n) if i != k]
        errors.append(fit(x[keep], y[keep]).getMetaModel()(x[k])[0] - y[k][0])
    mean = y.computeMean()[0]
    variance = sum((y[i][0] - mean) ** 2 for i in range(n)) / n
    q2 = 1.0 - sum(e * e for e in errors) / n / variance if variance > 0 else float("nan")
    result = fit(x, y)
    sobol = ot.FunctionalChaosSobolIndices(result)
    indices = {f["name"]: (float(sobol.getSobolIndex(j)), float(sobol.getSobolTotalIndex(j))) for j, f in enumerate(factors)}
    # The chaos's lowest and highest value over the whole box (every factor over its range or levels): where its Q2
    # validates it, how far the box can move the response.
    grid = box_grid(factors)
    values = result.getMetaModel()(grid)
    k_min = min(range(grid.getSize()), key=lambda i: values[i][0])
    k_max = max(range(grid.getSize()), key=lambda i: values[i][0])

    def at(k):
        return {f["name"]: value_at_unit(f, float(grid[k, j])) for j, f in enumerate(factors)}

    return {"response": response, "degree": degree, "terms": int(result.getIndices().getSize()), "leave_one_out_q2": q2, "sobol": indices,
            "validated": q2 >= MIN_Q2, "box_min": {"value": values[k_min][0], "at": at(k_min)}, "box_max": {"value": values[k_max][0], "at": at(k_max)}}


def chaos_or_none(study, rows, response):
    """The chaos of degree 2, else of degree 1 where too few points make the least squares singular; None if neither."""
    for degree in (2, 1):
        try:
            return pce_sobol(study, rows, response, degree)
        except (TypeError, RuntimeError):  # OpenTURNS' InvalidArgumentException: a singular least-squares system
            continue
    return None


def box_grid(factors, size=4096):
    """Points over the factors' box in unit coordinates: ranges over their whole span, levels at the levels only."""
    import openturns as ot
    dim = len(factors)
    grid = ot.LowDiscrepancyExperiment(ot.SobolSequence(dim), ot.ComposedDistribution([ot.Uniform(0.0, 1.0)] * dim), size, False).generate()
    for j, f in enumerate(factors):
        if "levels" in f:
            count = len(f["levels"])
            for i in range(grid.getSize()):
                grid[i, j] = min(int(grid[i, j] * count), count - 1) / (count - 1)
    return grid


def kriging_surrogate(study, rows, response, factor_names, noise_sd=None):
    """The response's kriging surrogate on the named factors, its leave-one-out Q2, and its lowest and highest value
    over the factors' box (the other factors averaged out)."""
    model, factors, q2, rmse = fit_kriging(study, rows, response, factor_names, noise_sd)
    grid = box_grid(factors)
    values = model(grid)

    def at(k):
        return {f["name"]: value_at_unit(f, float(grid[k, j])) for j, f in enumerate(factors)}

    k_min = min(range(grid.getSize()), key=lambda i: values[i][0])
    k_max = max(range(grid.getSize()), key=lambda i: values[i][0])
    return {"response": response, "factors": [f["name"] for f in factors], "points": len(rows),
            "leave_one_out_q2": q2, "leave_one_out_rmse": rmse, "replica_sd": noise_sd,
            "validated": surrogate_validated(q2, rmse, noise_sd),
            "box_min": {"value": values[k_min][0], "at": at(k_min)},
            "box_max": {"value": values[k_max][0], "at": at(k_max)},
            "observed_min": min(r[response] for r in rows), "observed_max": max(r[response] for r in rows)}


def calibrated_errors(ratios):
    """Each multi-bevel needle's deflection with SB calibrated to the experiment, to first order (delta_X = delta_SB,measured
    x ratio_X), less the measured one: {needle: error_mm}."""
    return {n: MEASURED_MM["SB"] * r - MEASURED_MM[n] for n, r in ratios.items()}


def joint_search(study, rows, factor_names, scatter=None):
    """The point of the box (the named factors; the others averaged out) whose surrogate ratios, calibrated on SB, come
    nearest the experiment: the largest |error| over the multi-bevel needles is the smallest."""
    scatter = scatter or {}
    needles = [n for n in study["needles"] if n != "SB"]
    fits = {n: fit_kriging(study, rows, f"ratio_{n}", factor_names, scatter.get(f"ratio_{n}")) for n in needles}
    factors = fits[needles[0]][1]
    grid = box_grid(factors, 8192)
    values = {n: fits[n][0](grid) for n in needles}
    best, best_score = 0, float("inf")
    for i in range(grid.getSize()):
        score = max(abs(e) for e in calibrated_errors({n: values[n][i][0] for n in needles}).values())
        if score < best_score:
            best, best_score = i, score
    ratios = {n: values[n][best][0] for n in needles}
    return {"factors": [f["name"] for f in factors],
            "leave_one_out_q2": {n: fits[n][2] for n in needles}, "leave_one_out_rmse": {n: fits[n][3] for n in needles},
            "validated": all(surrogate_validated(fits[n][2], fits[n][3], scatter.get(f"ratio_{n}")) for n in needles),
            "best_at": {f["name"]: value_at_unit(f, float(grid[best, j])) for j, f in enumerate(factors)},
            "best_ratios": ratios, "best_calibrated_errors_mm": calibrated_errors(ratios), "best_max_error_mm": best_score}


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
        values = [table[resp][n][0] for n in names]
        ax.bar([i + k * width for i in range(len(names))], values, width, label=resp)
        for i, n in enumerate(names):
            if table[resp][n][1] < 0.05:
                ax.text(i + k * width, values[i], "*", ha="center", va="bottom", fontsize=9)
    ax.set_xticks([i + 0.4 - width / 2 for i in range(len(names))])
    ax.set_xticklabels(names, rotation=40, ha="right", fontsize=8)
    ax.set_ylabel("R2-HSIC index")
    ax.set_title("Which unknowns move the deflections and the ratios to SB (* permutation p < 0.05)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_scatter(path, study, rows, table):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ratios = [r for r in responses(study) if r.startswith("ratio_")]
    fig, axes = plt.subplots(len(ratios), 3, figsize=(12, 3.2 * len(ratios)), squeeze=False)
    for i, resp in enumerate(ratios):
        top = sorted(table[resp].items(), key=lambda kv: -kv[1][0])[:3]
        needle = resp.split("_", 1)[1]
        for j, (name, (r2, p)) in enumerate(top):
            f = next(f for f in study["factors"] if f["name"] == name)
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


def analyze(study, out, permutations=2000, top=3, root=None):
    scatter = replica_scatter(study, root or os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")))
    records = read_points(study, out)
    rows, incomplete = complete_rows(study, records)
    folder = os.path.join(out, "analysis")
    os.makedirs(folder, exist_ok=True)
    write_csv(os.path.join(folder, "points.csv"), rows)
    if len(rows) < 4:
        raise StudyError(f"{len(rows)} complete design points in {out}: the analysis needs at least 4")
    resp = responses(study)
    table = {r: {name: (r2, p) for name, r2, p in hsic_indices(study, rows, r, permutations)} for r in resp}
    with open(os.path.join(folder, "hsic.csv.tmp"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["factor"] + [x for r in resp for x in (f"{r}_r2hsic", f"{r}_p")])
        for fac in study["factors"]:
            w.writerow([fac["name"]] + [f"{v:.6g}" for r in resp for v in table[r][fac["name"]]])
    os.replace(os.path.join(folder, "hsic.csv.tmp"), os.path.join(folder, "hsic.csv"))
    surrogates = []
    for r in [x for x in resp if x.startswith("ratio_") or x == PLATEAU]:
        names = [n for n, _ in sorted(table[r].items(), key=lambda kv: -kv[1][0])[:top]]
        surrogates.append(kriging_surrogate(study, rows, r, names, scatter.get(r)))
    chaos = [chaos_or_none(study, rows, r) for r in resp if r.startswith("ratio_")]
    chaos = [c for c in chaos if c]
    joint_factors = []
    for s_ in surrogates:
        joint_factors += [n for n in s_["factors"] if n not in joint_factors]
    joint = joint_search(study, rows, joint_factors, scatter)
    nearest = min(rows, key=lambda r: r["calibrated_max_error_mm"])
    result = {"points_complete": len(rows), "points_incomplete": [{"point": p, "needles": s} for p, s in incomplete],
              "responses": resp, "hsic": {r: {n: {"r2_hsic": v[0], "p_value": v[1]} for n, v in table[r].items()} for r in resp},
              "replica_sd": scatter, "surrogates": surrogates, "chaos": chaos, "joint": joint, "nearest_run_point": nearest, "measured_mm": MEASURED_MM}
    with open(os.path.join(folder, "surrogate.json.tmp"), "w") as f:
        json.dump(result, f, indent=1)
    os.replace(os.path.join(folder, "surrogate.json.tmp"), os.path.join(folder, "surrogate.json"))
    md = [f"# Global sensitivity: {len(rows)} complete design points x {len(study['needles'])} needles", ""]
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
            r2, p = table[r][fac["name"]]
            cell = f"{r2:.3f} ({p:.3f})"
            cells.append((f"**{cell}**" if p < 0.05 else cell) + (" †" if p < bonferroni else ""))
        md.append(f"| {fac['name']} | " + " | ".join(cells) + " |")
    md.append("")
    md.append("Kriging surrogates of the ratios to SB and of the plateau AMB - LMB on their three most influential factors (the others "
              "averaged out):")
    md.append("")
    md.append(f"(box min..max in brackets where the surrogate is not validated: its leave-one-out Q2 is below {MIN_Q2} and its leave-one-out "
              f"RMSE above {RMSE_OVER_SCATTER} times the replicas' standard deviation, where the study names replicas"
              + (f" ({study['scatter_from']} and its replicas; the kriging takes that scatter as the runs' noise)" if scatter else "") + ")")
    md.append("")
    md.append("| response | factors | LOO Q2 | LOO RMSE | replicas' SD | observed min..max | box min..max | experiment |")
    md.append("|---|---|---|---|---|---|---|---|")
    for s in surrogates:
        experiment = (MEASURED_MM["AMB"] - MEASURED_MM["LMB"] if s["response"] == PLATEAU
                      else MEASURED_MM[s["response"].split("_", 1)[1]] / MEASURED_MM["SB"])
        md.append(f"| {s['response']} | {', '.join(s['factors'])} | {s['leave_one_out_q2']:.2f} | {s['leave_one_out_rmse']:.3f} | "
                  + (f"{s['replica_sd']:.3f}" if s["replica_sd"] else "-") + " | "
                  + f"{s['observed_min']:+.3f}..{s['observed_max']:+.3f} | "
                  + (f"{s['box_min']['value']:+.3f}..{s['box_max']['value']:+.3f}" if s["validated"] else
                     f"({s['box_min']['value']:+.3f}..{s['box_max']['value']:+.3f})")
                  + f" | {experiment:+.3f} |")
    md.append("")
    md.append("Sparse additive polynomial chaos of each ratio over all the factors (each factor's polynomials to degree 2, or 1 where too few points, no interactions; LARS): first-order / total Sobol' indices of the "
              "factors with a total index of at least 0.05, and the chaos's leave-one-out Q2 (below about 0.5 the indices say little):")
    md.append("")
    for c in chaos:
        big = sorted(((n, v) for n, v in c["sobol"].items() if v[1] >= 0.05), key=lambda kv: -kv[1][1])
        md.append(f"- {c['response']} (degree {c['degree']}, Q2 {c['leave_one_out_q2']:.2f}, {c['terms']} terms): "
                  + (", ".join(f"{n} {v[0]:.2f} / {v[1]:.2f}" for n, v in big) if big else "no factor reaches 0.05")
                  + (f"; over the whole box {c['box_min']['value']:+.3f}..{c['box_max']['value']:+.3f} (lowest at "
                     + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in c["box_min"]["at"].items()) + ")"
                     if c["validated"] else ""))
    md.append("")
    md.append("Calibrated on SB to first order (each needle's deflection = the measured SB's x its ratio to SB), against the experiment:")
    md.append("")
    md.append(f"- the run design point nearest the experiment: point {nearest['point']}, largest error {nearest['calibrated_max_error_mm']:.3f} mm ("
              + ", ".join(f"{n} {nearest[f'calibrated_error_{n}_mm']:+.3f}" for n in study["needles"] if n != "SB") + ")")
    md.append(("- " if joint["validated"] else "- NOT VALIDATED (a ratio's surrogate is not validated: its best point is no finding): ")
              + f"the surrogates' best point over {', '.join(joint['factors'])} (LOO Q2 "
              + ", ".join(f"{n} {q:.2f}" for n, q in joint["leave_one_out_q2"].items()) + f"): largest error {joint['best_max_error_mm']:.3f} mm ("
              + ", ".join(f"{n} {e:+.3f}" for n, e in joint["best_calibrated_errors_mm"].items()) + ") at "
              + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in joint["best_at"].items()))
    if PLATEAU in resp:
        values = [r[PLATEAU] for r in rows]
        md.append(f"- AMB - LMB with SB calibrated, over the run points: {min(values):+.3f} to {max(values):+.3f} mm (the experiment: "
                  f"{MEASURED_MM['AMB'] - MEASURED_MM['LMB']:+.2f} +- 0.05 mm)")
    md.append(f"- two standard deviations of the experiment: {2 * POOLED_SD_MM:.2f} mm")
    md.append("")
    with open(os.path.join(folder, "hsic.md"), "w") as f:
        f.write("\n".join(md))
    plot_hsic(os.path.join(folder, "hsic.png"), study, table, resp)
    plot_scatter(os.path.join(folder, "ratio_scatter.png"), study, rows, table)
    print("\n".join(md))
    return result


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.normpath(os.path.join(here, "..", ".."))
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--study", default=os.path.join(root, "data", "studies", "global_sensitivity.json"), help="the study file")
    p.add_argument("--out", required=True, help="the study folder (created; reruns resume)")
    p.add_argument("--batches", type=int, default=1, help="run batches 0..N-1 of the design (default 1)")
    p.add_argument("--jobs", type=int, default=2, help="worker processes of each sweep (default 2)")
    p.add_argument("--threads", type=int, default=0, help="threads a case (default: the cores divided among the jobs)")
    p.add_argument("--mpi", type=int, default=0, help="run each sweep on N MPI workers instead of --jobs")
    p.add_argument("--needle", default=os.path.join(root, "build", "apps", "needle"), help="the needle command")
    p.add_argument("--design-only", action="store_true", help="write the sweep files only")
    p.add_argument("--analyze-only", action="store_true", help="analyse the finished cases only")
    p.add_argument("--permutations", type=int, default=2000, help="permutations of the HSIC p-values (default 2000)")
    args = p.parse_args(argv)
    try:
        study = read_study(args.study)
        if args.batches < 1:
            raise StudyError("--batches must be at least 1")
        if not args.analyze_only:
            for b in range(args.batches):
                path = write_batch(study, args.out, b)
                if not args.design_only:
                    if not os.access(args.needle, os.X_OK):
                        raise StudyError(f"{args.needle}: no needle command (build it: bash scripts/build.sh needle)")
                    run_batch(args, path)
        if not args.design_only:
            analyze(study, args.out, args.permutations)
    except StudyError as e:
        print(f"global_sensitivity: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
