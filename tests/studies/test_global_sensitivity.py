#!/usr/bin/python3
"""Tests of studies/sensitivity/global_sensitivity.py (the global sensitivity study of the paper's unknowns).

- The design: ranges map linearly, levels take equal shares of [0, 1); batch k+1 extends batches 0..k; every needle
  of a point gets the same values; the sweep file of a batch is accepted by `needle sweep --count` (the scene reader
  checks every key and value) and counts points x needles cases.
- The statistics, on a study whose "runs" are a known function written as case records: the HSIC screen finds the
  two factors the ratios depend on (p < 0.01) and gives the inert ones a far smaller index, and the kriging surrogate
  of a smooth ratio predicts left-out points (Q2 > 0.9) and reaches the function's own extremes over the box, the
  additive polynomial chaos gives the closed form's Sobol' indices, and the joint search finds the function's minimax.
- A box point's distance from the nearest run and the runs' spacing (an extrapolation flag) on known layouts.
- A partial batch (--points) is the whole batch's first points, which the whole batch later extends. The held-out
  check predicts batch 1 from batch 0 before it runs, the runs leave the predictions as they were, the known function's
  predictions hold and an offset of 0.3 in batch 1's ratios fails the check.
- The box's corners as a batch ("corners"): the half fraction's defining relation and projections, the other factors at
  their middle, the corners predicted before they run from the points below the declared bound (and refused with one
  line where the study file's "corners" is wrong); --batch K runs that batch alone.
- One more parameter fitted honestly (second_parameter.py): on ratios linear in the value, each fit and each held-out
  prediction has a closed form; its sweep file passes `needle sweep --count`.
- Bad study files are refused with one line and exit 2.
Usage: test_global_sensitivity.py NEEDLE_BINARY SOURCE_DIR. Exit 77 (skipped) without python3-openturns.
"""
import json
import os
import subprocess
import sys
import tempfile

needle, source = sys.argv[1], sys.argv[2]
try:
    import openturns  # noqa: F401
except ImportError:
    print("skipped: python3-openturns is not installed")
    sys.exit(77)
sys.path.insert(0, os.path.join(source, "studies", "sensitivity"))
import global_sensitivity as gs  # noqa: E402

failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


study = gs.read_study(os.path.join(source, "data", "studies", "global_sensitivity.json"))

# The design.
check(gs.factor_value({"range": [2.0, 4.0]}, 0.25) == 2.5, "a range maps u linearly")
check([gs.factor_value({"levels": ["a", "b", "c"]}, u) for u in (0.0, 0.34, 0.67, 0.999)] == ["a", "b", "c", "c"],
      "levels take equal shares of [0, 1)")
n = study["batch_points"]
first_two = gs.unit_design(len(study["factors"]), 2 * n)
check(gs.unit_design(len(study["factors"]), n) == first_two[:n], "batch 1 extends batch 0 without moving it")
check(all(0.0 <= v < 1.0 for row in first_two for v in row), "the unit design lies in [0, 1)")
cases = gs.batch_cases(study, 1)
check(len(cases) == n * len(study["needles"]) and cases[0][0] == n, "batch 1 holds points n..2n-1 on every needle")
by_point = {}
for point, needle_name, values in cases:
    by_point.setdefault(point, []).append(values)
check(all(all(v == vs[0] for v in vs) for vs in by_point.values()), "every needle of a point gets the same values")
for f in study["factors"]:
    for point, _, values in cases:
        v = values[f["key"]]
        inside = (f["range"][0] <= v <= f["range"][1]) if "range" in f else (v in f["levels"])
        if not inside:
            check(False, f"{f['name']} = {v} lies in its range")
            break

with tempfile.TemporaryDirectory() as tmp:
    path = gs.write_batch(study, tmp, 0)
    count = subprocess.run([needle, "sweep", path, "--count"], capture_output=True, text=True)
    check(count.returncode == 0 and count.stdout.strip() == str(n * len(study["needles"])),
          f"needle sweep --count accepts batch 0's sweep file ({count.stdout.strip()} cases{', ' + count.stderr.strip() if count.stderr else ''})")
    check(gs.write_batch(study, tmp, 0) == path, "writing the same batch again is accepted")

# The statistics on a known function. Ratios depend on two factors only (friction and groove_start_mm), smoothly;
# the deflections scale with E. Every other factor is inert.
def truth(values):
    fr = (values["tissue.friction"] - 0.05) / 0.35
    gsm = (values["needle.groove_start_mm"] - 3.0) / 3.0
    e = values["tissue.material.E_MPa"]
    sb = -1.14 * e / 0.0884
    ratio = {"LMB": -0.5 + 0.6 * gsm, "AMB": -1.3 + 0.8 * gsm + 0.5 * fr * fr, "HMB": -2.2 + 0.4 * fr}
    out = {"SB": sb}
    out.update({k: v * sb for k, v in ratio.items()})
    return out, ratio


with tempfile.TemporaryDirectory() as tmp:
    small = dict(study)
    small["batch_points"] = 32
    gs.write_batch(small, tmp, 0)
    for index, (point, needle_name, values) in enumerate(gs.batch_cases(small, 0)):
        case_dir = os.path.join(tmp, "batch_0", "sweep", "cases", f"case_{index:04d}")
        os.makedirs(case_dir)
        deflection, _ = truth(values)
        record = {"label": f"point {point:03d} {needle_name}", "status": "finished", "deflection_mm": deflection[needle_name],
                  "groove_fill": 0.9, "runtime_s": 1.0}
        # One point's HMB stops: the point must be left out and reported incomplete.
        if point == 5 and needle_name == "HMB":
            record = {"label": record["label"], "status": "stopped", "reason": "energy drift", "deflection_mm": None}
        with open(os.path.join(case_dir, "case.json"), "w") as f:
            json.dump(record, f)
    result = gs.analyze(small, tmp, permutations=400)
    check(result["points_complete"] == 31 and result["points_incomplete"][0]["point"] == 5,
          "a point with a stopped needle is left out and listed as incomplete")
    hsic = result["hsic"]
    for response, drivers in (("ratio_LMB", ["groove_start_mm"]), ("ratio_AMB", ["groove_start_mm", "friction"]), ("ratio_HMB", ["friction"]),
                              ("delta_SB_mm", ["E_MPa"])):
        top = max(hsic[response].items(), key=lambda kv: kv[1]["r2_hsic"])
        check(top[0] in drivers and top[1]["p_value"] < 0.01, f"{response}: the top factor is a driver ({top[0]}, p {top[1]['p_value']:.3f})")
        inert = [v["r2_hsic"] for k, v in hsic[response].items() if k not in drivers and k != "E_MPa"]
        check(max(inert) < 0.3 * top[1]["r2_hsic"], f"{response}: every inert factor's index is below 0.3 of the driver's ({max(inert):.3f})")
    amb = next(s for s in result["surrogates"] if s["response"] == "ratio_AMB")
    check(set(["groove_start_mm", "friction"]) <= set(amb["factors"]), f"the AMB surrogate takes its two drivers ({amb['factors']})")
    check(amb["leave_one_out_q2"] > 0.9, f"the AMB surrogate predicts left-out points (Q2 {amb['leave_one_out_q2']:.3f})")
    check(abs(amb["box_min"]["value"] - (-1.3)) < 0.05 and abs(amb["box_max"]["value"] - (-1.3 + 0.8 + 0.5)) < 0.05,
          f"the AMB surrogate reaches the function's extremes over the box ({amb['box_min']['value']:.3f}, {amb['box_max']['value']:.3f})")
    # The chaos of AMB's ratio is exact (the function is of degree 2 in the scaled factors): its Sobol' indices are the
    # closed form's, Var(0.8 g) / Var and Var(0.5 f^2) / Var with g, f uniform on [0, 1].
    var_g, var_f = 0.64 / 12, 0.25 * (1 / 5 - 1 / 9)
    chaos = next(c for c in result["chaos"] if c["response"] == "ratio_AMB")
    check(chaos["leave_one_out_q2"] > 0.9, f"the chaos of AMB's ratio predicts left-out points (Q2 {chaos['leave_one_out_q2']:.3f}, degree {chaos['degree']})")
    check(abs(chaos["sobol"]["groove_start_mm"][0] - var_g / (var_g + var_f)) < 0.05 and abs(chaos["sobol"]["friction"][1] - var_f / (var_g + var_f)) < 0.05,
          f"its Sobol' indices are the closed form's (groove {chaos['sobol']['groove_start_mm'][0]:.3f} against {var_g / (var_g + var_f):.3f}, "
          f"friction {chaos['sobol']['friction'][1]:.3f} against {var_f / (var_g + var_f):.3f})")
    check(chaos["validated"] and abs(chaos["box_min"]["value"] - (-1.3)) < 0.03 and abs(chaos["box_max"]["value"] - 0.0) < 0.03,
          f"the chaos of AMB's ratio reaches the function's extremes over the whole box ({chaos['box_min']['value']:.3f}, "
          f"{chaos['box_max']['value']:.3f} against -1.3, 0.0)")
    # The joint search's best point against the function's own minimax, by brute force over its two drivers.
    best = float("inf")
    for i in range(201):
        for j in range(201):
            fr, gsm = i / 200, j / 200
            values = {"tissue.friction": 0.05 + 0.35 * fr, "needle.groove_start_mm": 3.0 + 3.0 * gsm, "tissue.material.E_MPa": 0.0884}
            _, ratio = truth(values)
            best = min(best, max(abs(-1.14 * ratio[k] - gs.MEASURED_MM[k]) for k in ratio))
    joint = result["joint"]
    check(abs(joint["best_max_error_mm"] - best) < 0.03,
          f"the joint search finds the function's smallest largest error over the box ({joint['best_max_error_mm']:.3f} against {best:.3f} mm)")
    for name in ("points.csv", "hsic.csv", "hsic.md", "surrogate.json", "hsic.png", "ratio_scatter.png"):
        check(os.path.getsize(os.path.join(tmp, "analysis", name)) > 0, f"analysis/{name} is written")

# How far a box point lies from the runs: the nearest run and the runs' own spacing (the median nearest neighbour), in
# unit coordinates; a point farther out than the runs' spacing is an extrapolation.
square = [{"a": x, "b": 2.0 * y} for x in (0.0, 1.0) for y in (0.0, 1.0)]
unit_factors = [{"name": "a", "range": [0.0, 1.0]}, {"name": "b", "range": [0.0, 2.0]}]
inside = gs.run_distances(unit_factors, square, [0.5, 0.5])
check(abs(inside["nearest_run"] - 0.5 ** 0.5) < 1e-12 and abs(inside["run_spacing"] - 1.0) < 1e-12 and not inside["extrapolated"],
      f"the square's centre lies sqrt(1/2) from its corners, which lie 1 apart: not an extrapolation ({inside})")
clustered = [{"a": 0.0, "b": 0.0}, {"a": 0.1, "b": 0.0}, {"a": 0.0, "b": 0.2}]
far = gs.run_distances(unit_factors, clustered, [1.0, 1.0])
check(abs(far["nearest_run"] - (0.9 ** 2 + 1.0) ** 0.5) < 1e-12 and abs(far["run_spacing"] - 0.1) < 1e-12 and far["extrapolated"],
      f"a corner far from runs 0.1 apart is an extrapolation ({far})")

# Runs that scatter (a lattice's phase, rounding): the replicas' standard deviation, and a kriging that takes it as noise.
with tempfile.TemporaryDirectory() as tmp:
    reports = {"main.json": (-1.0, 0.10, 0.30), "r1.json": (-1.1, 0.05, 0.35), "r2.json": (-0.9, 0.20, 0.20)}
    for name, (sb, lmb, amb) in reports.items():
        body = {"needles": {"SB": {"status": "finished", "deflection_mm": sb}, "LMB": {"status": "finished", "deflection_mm": lmb},
                            "AMB": {"status": "finished", "deflection_mm": amb}}}
        if name == "main.json":
            body["replicas"] = [{"label": "a", "results": "r1.json"}, {"label": "b", "results": "r2.json"}]
        with open(os.path.join(tmp, name), "w") as f:
            json.dump(body, f)
    three = {"needles": ["SB", "LMB", "AMB"], "factors": study["factors"], "batch_points": 4, "scatter_from": "main.json"}
    sd = gs.replica_scatter(three, tmp)
    lmb_ratios = [lmb / sb for sb, lmb, _ in reports.values()]
    mean = sum(lmb_ratios) / 3
    check(abs(sd["ratio_LMB"] - (sum((r - mean) ** 2 for r in lmb_ratios) / 2) ** 0.5) < 1e-12 and abs(sd["delta_SB_mm"] - 0.1) < 1e-12,
          f"the replicas' standard deviation of a ratio and of a deflection (ratio_LMB {sd['ratio_LMB']:.4f}, delta_SB {sd['delta_SB_mm']:.4f})")
    try:
        gs.replica_scatter(dict(three, scatter_from="missing.json"), tmp)
        check(False, "a missing scatter_from is refused")
    except gs.StudyError as e:
        check("missing.json" in str(e), f"a missing scatter_from is refused ({e})")

# A known smooth ratio plus a known noise (a fixed pseudo-random sequence, SD 0.05): with the noise given, the kriging
# smooths it, is validated by its leave-one-out error against the noise, and finds the function's extremes; the same
# points given a noise four times smaller than they carry are not validated.
import random  # noqa: E402
noise_rng = random.Random(7)
design = {"batch_points": 48, **{k: v for k, v in study.items() if k != "batch_points"}}
rows = []
for point, needle_name, values in gs.batch_cases(design, 0):
    if needle_name != "SB":
        continue
    row = {f["name"]: values[f["key"]] for f in design["factors"]}
    _, ratio = truth(values)
    row["ratio_LMB"] = ratio["LMB"] + noise_rng.gauss(0.0, 0.05)
    rows.append(row)
smooth = gs.kriging_surrogate(design, rows, "ratio_LMB", ["groove_start_mm", "friction"], noise_sd=0.05)
check(smooth["validated"] and smooth["leave_one_out_rmse"] < 1.5 * 0.05,
      f"noisy runs: the kriging given the noise is validated (LOO RMSE {smooth['leave_one_out_rmse']:.3f}, Q2 {smooth['leave_one_out_q2']:.2f})")
check(abs(smooth["box_min"]["value"] - (-0.5)) < 0.05 and abs(smooth["box_max"]["value"] - 0.1) < 0.05,
      f"noisy runs: the surrogate's extremes are the function's, not the noise's ({smooth['box_min']['value']:+.3f}, {smooth['box_max']['value']:+.3f} "
      f"against -0.5, +0.1; the runs span {smooth['observed_min']:+.3f}..{smooth['observed_max']:+.3f})")
overclaimed = gs.kriging_surrogate(design, [dict(r, ratio_LMB=r["ratio_LMB"] + noise_rng.gauss(0.0, 0.2)) for r in rows], "ratio_LMB",
                                   ["groove_start_mm", "friction"], noise_sd=0.05)
check(not overclaimed["validated"],
      f"runs four times noisier than the replicas say are not validated (LOO RMSE {overclaimed['leave_one_out_rmse']:.3f}, Q2 {overclaimed['leave_one_out_q2']:.2f})")

# Replicas: each point run again with scene keys set on top (the lattice shifted). The plain batch's sweep file is the
# same with or without them; a replica's adds its keys and keeps the labels; a response is the mean of a point's
# complete runs; the scatter between a point's own runs, pooled, recovers a known noise; the kriging given it smooths
# the means and is validated.
replicated = dict(study, batch_points=32, replicas=[{"name": "y0.1", "set": {"tissue.offset_y_mm": 0.1}}])
plain_study = dict(study, batch_points=32)
with tempfile.TemporaryDirectory() as tmp:
    check(gs.sweep_file(replicated, 0) == gs.sweep_file(plain_study, 0), "replicas leave the plain batch's sweep file as it was")
    shifted_file = gs.sweep_file(replicated, 0, "y0.1")
    check(shifted_file["set"] == dict(study.get("set", {}), **{"tissue.offset_y_mm": 0.1})
          and [c["label"] for c in shifted_file["design"]["cases"]] == [c["label"] for c in gs.sweep_file(plain_study, 0)["design"]["cases"]],
          "a replica's sweep file sets its keys on top of the study's and keeps the points' labels")
    path = gs.write_batch(replicated, tmp, 0, "y0.1")
    count = subprocess.run([needle, "sweep", path, "--count"], capture_output=True, text=True)
    check(path.endswith(os.path.join("batch_0_y0.1", "sweep.json")) and count.returncode == 0 and count.stdout.strip() == str(32 * len(study["needles"])),
          f"needle sweep --count accepts the replica's sweep file ({count.stdout.strip()} cases{', ' + count.stderr.strip() if count.stderr else ''})")
    gs.write_batch(replicated, tmp, 0)
    rng = random.Random(11)
    drawn = {}
    for replica in gs.replica_names(replicated):
        for index, (point, needle_name, values) in enumerate(gs.batch_cases(replicated, 0)):
            case_dir = os.path.join(gs.batch_folder(tmp, 0, replica), "sweep", "cases", f"case_{index:04d}")
            os.makedirs(case_dir)
            deflection, ratio = truth(values)
            if needle_name == "LMB":  # the ratio itself carries the noise: SD 0.05
                drawn[(point, replica)] = ratio["LMB"] + rng.gauss(0.0, 0.05)
                deflection["LMB"] = drawn[(point, replica)] * deflection["SB"]
            record = {"label": f"point {point:03d} {needle_name}", "status": "finished", "deflection_mm": deflection[needle_name],
                      "groove_fill": 0.9, "runtime_s": 1.0}
            if replica and point == 7 and needle_name == "AMB":  # the replica of point 7 stops: the plain run stands alone
                record = {"label": record["label"], "status": "stopped", "reason": "energy drift", "deflection_mm": None}
            with open(os.path.join(case_dir, "case.json"), "w") as f:
                json.dump(record, f)
    rows, incomplete = gs.complete_rows(replicated, gs.read_points(replicated, tmp))
    row3 = next(r for r in rows if r["point"] == 3)
    row7 = next(r for r in rows if r["point"] == 7)
    check(len(rows) == 32 and not incomplete and row3["runs"] == 2 and row7["runs"] == 1,
          f"a point counts its complete runs (point 3: {row3['runs']}, point 7 with its replica stopped: {row7['runs']})")
    check(abs(row3["ratio_LMB"] - (drawn[(3, "")] + drawn[(3, "y0.1")]) / 2) < 1e-12 and abs(row7["ratio_LMB"] - drawn[(7, "")]) < 1e-12
          and row3["ratio_LMB@y0.1"] == row3["ratio_LMB@y0.1"] and row7["ratio_LMB@y0.1"] is None,
          "a response is the mean of the point's complete runs, each run's kept beside")
    within = gs.within_point_scatter(replicated, rows)
    sd_lmb, dof_lmb = within["ratio_LMB"]
    check(dof_lmb == 31 and abs(sd_lmb - 0.05) < 0.3 * 0.05 and within["ratio_HMB"][0] < 1e-9,
          f"the scatter within points recovers the noise (ratio_LMB {sd_lmb:.4f} with {dof_lmb} dof against 0.05; a noiseless ratio {within['ratio_HMB'][0]:.1e})")
    means = gs.kriging_surrogate(replicated, rows, "ratio_LMB", ["groove_start_mm", "friction"], noise_sd=sd_lmb)
    check(abs(means["data_sd"] - sd_lmb * ((31 / 2 + 1) / 32) ** 0.5) < 1e-12,
          f"the means' noise is one run's over the square root of the runs they average ({means['data_sd']:.4f})")
    check(means["validated"] and abs(means["box_min"]["value"] - (-0.5)) < 0.05 and abs(means["box_max"]["value"] - 0.1) < 0.05,
          f"replicated runs: the kriging of the means is validated and finds the function's extremes (LOO RMSE {means['leave_one_out_rmse']:.3f}, "
          f"{means['box_min']['value']:+.3f}..{means['box_max']['value']:+.3f} against -0.5..+0.1)")
    result = gs.analyze(replicated, tmp, permutations=200)
    check(abs(result["within_point_sd"]["ratio_LMB"]["sd"] - sd_lmb) < 1e-12 and abs(result["replica_sd"]["ratio_LMB"] - sd_lmb) < 1e-12,
          "the analysis takes the scatter within points as the runs' noise")
    with open(os.path.join(tmp, "analysis", "hsic.md")) as f:
        check("share of the runs' variance within points" in f.read(), "the analysis's tables show the scatter within points")

# A factor that acts within the lip (a depth below tip point A): on a needle it acts only up to that needle's lip
# thickness (the runs' summary.json), beyond it the run is the same. AMB's ratio (lip 0.43 mm) sees the depth clipped at
# 0.43; LMB's (lip 0.21, the range starting at 0.2) and SB's cannot see it at all. With the clip the kriging follows
# the hinge and the joint search finds the function's own minimax.
lip_study = {"needles": ["SB", "LMB", "AMB"], "batch_points": 32,
             "factors": [{"name": "groove_start_mm", "key": "needle.groove_start_mm", "range": [3.0, 6.0]},
                         {"name": "crushed_depth_mm", "key": "tissue.contact.lip_release_depth_mm", "range": [0.2, 0.8], "acts_within_lip": True}]}
LIPS = {"SB": None, "LMB": 0.21, "AMB": 0.43}


def lip_truth(values):
    g = (values["needle.groove_start_mm"] - 3.0) / 3.0
    d = min(values["tissue.contact.lip_release_depth_mm"], 0.43)
    return {"LMB": -0.5 + 0.6 * g, "AMB": -0.4 + 0.3 * g + 1.5 * (0.43 - d)}


with tempfile.TemporaryDirectory() as tmp:
    gs.write_batch(lip_study, tmp, 0)
    for index, (point, needle_name, values) in enumerate(gs.batch_cases(lip_study, 0)):
        case_dir = os.path.join(tmp, "batch_0", "sweep", "cases", f"case_{index:04d}")
        os.makedirs(os.path.join(case_dir, "run"))
        ratio = lip_truth(values)
        deflection = -1.14 if needle_name == "SB" else -1.14 * ratio[needle_name]
        with open(os.path.join(case_dir, "case.json"), "w") as f:
            json.dump({"label": f"point {point:03d} {needle_name}", "status": "finished", "deflection_mm": deflection,
                       "groove_fill": 0.9, "runtime_s": 1.0}, f)
        summary = {"groove": {"floor_contact_fraction": 0.1}}
        if LIPS[needle_name] is not None:
            summary["lip_release"] = {"lip_thickness_mm": LIPS[needle_name]}
        with open(os.path.join(case_dir, "run", "summary.json"), "w") as f:
            json.dump(summary, f)
    rows, _ = gs.complete_rows(lip_study, gs.read_points(lip_study, tmp))
    amb_study, amb_rows = gs.response_view(lip_study, rows, "ratio_AMB")
    depth = next(f for f in amb_study["factors"] if f["name"] == "crushed_depth_mm")
    check(depth["range"] == [0.2, 0.43] and all(r["crushed_depth_mm"] == min(o["crushed_depth_mm"], 0.43) for r, o in zip(amb_rows, rows)),
          f"AMB's ratio sees the depth clipped at its lip's 0.43 mm (range {depth['range']})")
    lmb_study, _ = gs.response_view(lip_study, rows, "ratio_LMB")
    sb_study, _ = gs.response_view(lip_study, rows, "delta_SB_mm")
    check([f["name"] for f in lmb_study["factors"]] == ["groove_start_mm"] and [f["name"] for f in sb_study["factors"]] == ["groove_start_mm"],
          "LMB's ratio (lip 0.21 mm, the range from 0.2) and SB's deflection (no lip) cannot see the depth: it is left out")
    plateau_study, _ = gs.response_view(lip_study, rows, gs.PLATEAU)
    check(next(f for f in plateau_study["factors"] if f["name"] == "crushed_depth_mm")["range"] == [0.2, 0.43],
          "the plateau sees the depth up to its thickest lip, AMB's")
    amb = gs.kriging_surrogate(amb_study, amb_rows, "ratio_AMB", ["groove_start_mm", "crushed_depth_mm"])
    check(amb["leave_one_out_q2"] > 0.9 and abs(amb["box_max"]["value"] - (-0.1 + 1.5 * 0.23)) < 0.03,
          f"the clipped kriging follows the hinge (Q2 {amb['leave_one_out_q2']:.3f}, box max {amb['box_max']['value']:+.3f} against {-0.1 + 1.5 * 0.23:+.3f})")
    best = min(max(abs(-1.14 * v - gs.MEASURED_MM[k]) for k, v in lip_truth({"needle.groove_start_mm": 3.0 + 3.0 * i / 200,
                                                                              "tissue.contact.lip_release_depth_mm": 0.2 + 0.6 * j / 200}).items())
               for i in range(201) for j in range(201))
    joint = gs.joint_search(lip_study, rows, ["groove_start_mm", "crushed_depth_mm"])
    check(abs(joint["best_max_error_mm"] - best) < 0.03,
          f"the joint search over the clipped depth finds the function's smallest largest error ({joint['best_max_error_mm']:.3f} against {best:.3f} mm)")
    result = gs.analyze(lip_study, tmp, permutations=200)
    check(result["hsic"]["ratio_AMB"]["crushed_depth_mm"]["p_value"] < 0.01 and "crushed_depth_mm" not in result["hsic"]["ratio_LMB"],
          "the analysis screens the depth on AMB's ratio and leaves it out of LMB's")

    # A region of the box (--region): the points where the depth crushes AMB's lip whole, the depth's range narrowed to
    # them. There the depth cannot act on any needle, so it drops out, and AMB's surrogate is the groove's line alone.
    region = gs.analyze(lip_study, tmp, permutations=200, regions=[("crushed_depth_mm", 0.43, 0.8)])
    inside = [r for r in rows if r["crushed_depth_mm"] >= 0.43]
    check(region["points_complete"] == len(inside) and 8 <= len(inside) < len(rows),
          f"the region holds the points with the depth at 0.43 mm or more ({region['points_complete']} of {len(rows)}: {len(inside)})")
    check(all("crushed_depth_mm" not in region["hsic"][r] for r in region["responses"]),
          "within the region the depth acts on no needle: it is left out of every response")
    amb_region = next(s_ for s_ in region["surrogates"] if s_["response"] == "ratio_AMB")
    check(amb_region["factors"] == ["groove_start_mm"] and amb_region["leave_one_out_q2"] > 0.9
          and abs(amb_region["box_min"]["value"] - (-0.4)) < 0.02 and abs(amb_region["box_max"]["value"] - (-0.1)) < 0.02,
          f"the region's AMB surrogate is the groove's line, -0.4..-0.1 ({amb_region['factors']}, Q2 {amb_region['leave_one_out_q2']:.3f}, "
          f"{amb_region['box_min']['value']:+.3f}..{amb_region['box_max']['value']:+.3f})")
    check(os.path.getsize(os.path.join(tmp, "analysis_region_crushed_depth_mm_0.43_0.8", "hsic.md")) > 0
          and os.path.getsize(os.path.join(tmp, "analysis", "hsic.md")) > 0,
          "the region's tables go to their own folder beside the whole box's")
    lip_file = os.path.join(tmp, "lip_study.json")
    with open(lip_file, "w") as f:
        json.dump(lip_study, f)
    for extra, words in ((["--analyze-only", "--region", "nosuch=1,2"], "FACTOR=LO,HI"),
                         (["--analyze-only", "--region", "crushed_depth_mm=0.1,0.5"], "range"),
                         (["--analyze-only", "--region", "crushed_depth_mm=0.5,0.4"], "LO < HI"),
                         (["--region", "crushed_depth_mm=0.43,0.8"], "--analyze-only")):
        r = subprocess.run([sys.executable, os.path.join(source, "studies", "sensitivity", "global_sensitivity.py"), "--study", lip_file,
                            "--out", tmp] + extra, capture_output=True, text=True)
        check(r.returncode == 2 and words in r.stderr and "Traceback" not in r.stderr,
              f"{' '.join(extra)}: one clear error ({r.stderr.strip()})")

# A partial batch (--points N): its sweep file is the whole batch's first N points; the whole batch later replaces it
# (needle sweep then runs only the cases it has not recorded), and a shorter one after it is refused.
with tempfile.TemporaryDirectory() as tmp:
    part = gs.sweep_file(study, 1, "", 3)
    whole = gs.sweep_file(study, 1)
    check(part["design"]["cases"] == whole["design"]["cases"][:3 * len(study["needles"])] and part["set"] == whole["set"],
          "a partial batch's sweep file is the whole batch's first points")
    gs.write_batch(study, tmp, 1, "", 3)
    path = gs.write_batch(study, tmp, 1)
    with open(path) as f:
        check(json.load(f) == whole, "the whole batch replaces its partial sweep file")
    try:
        gs.write_batch(study, tmp, 1, "", 3)
        check(False, "a partial batch after the whole one is refused")
    except gs.StudyError as e:
        check("--points" in str(e), f"a partial batch after the whole one is refused ({e})")

# The held-out check ("held_out": {"from_batch": 1}): fitted on batch 0 alone, the surrogates predict batch 1's points
# from the design, before any of them has run; as they run, the observed means are set beside. On the known smooth
# function the predictions hold (validated, errors within the sd); where batch 1's runs are offset by 0.3 (the model
# not what batch 0 showed), the check fails. The linear trend (kriging_trend) follows a ratio linear in a factor.
def write_truth_records(design, folder, batch, points_limit=None, offset=0.0):
    """A batch's sweep file and the known function's case records, as `needle sweep` writes them; offset shifts every
    multi-bevel needle's ratio to SB (the model not what the fitted points showed)."""
    gs.write_batch(design, folder, batch, "", points_limit)
    for index, (point, needle_name, values) in enumerate(gs.batch_cases(design, batch, points_limit)):
        case_dir = os.path.join(folder, f"batch_{batch}", "sweep", "cases", f"case_{index:04d}")
        os.makedirs(case_dir, exist_ok=True)
        deflection, _ = truth(values)
        value = deflection[needle_name] + (offset * deflection["SB"] if needle_name != "SB" else 0.0)  # the ratio + offset
        with open(os.path.join(case_dir, "case.json"), "w") as f:
            json.dump({"label": f"point {point:03d} {needle_name}", "status": "finished", "deflection_mm": value,
                       "groove_fill": 0.9, "runtime_s": 1.0}, f)


def stored_predictions(folder, name):
    """Each point's predictions and their sd in analysis/NAME.csv (its last nine columns: three responses' predicted,
    sd, observed), the observed left out: what must not move when the held-out points run."""
    with open(os.path.join(folder, "analysis", f"{name}.csv")) as f:
        return [[cell for i, cell in enumerate(line.split(",")[-9:]) if i % 3 != 2] for line in f.read().splitlines()[1:]]


with tempfile.TemporaryDirectory() as tmp:
    held = dict(study, batch_points=24, kriging_trend="linear", held_out={"from_batch": 1})

    def write_records(batch, points_limit=None, offset=0.0):
        write_truth_records(held, tmp, batch, points_limit, offset)

    write_records(0)
    gs.write_batch(held, tmp, 1, "", 8)
    before = gs.analyze(held, tmp, permutations=200)["held_out"]
    check(before["fitted_points"] == 24 and len(before["points"]) == 24 and before["responses"]["ratio_AMB"]["observed_points"] == 0,
          "the held-out points are predicted before they run")
    with open(os.path.join(tmp, "analysis", "held_out.csv")) as f:
        predicted_before = [line.split(",")[7:9] for line in f.read().splitlines()[1:]]
    write_records(1, 8)
    after = gs.analyze(held, tmp, permutations=200)
    ok = after["held_out"]["responses"]
    with open(os.path.join(tmp, "analysis", "held_out.csv")) as f:
        predicted_after = [line.split(",")[7:9] for line in f.read().splitlines()[1:]]
    check(predicted_after == predicted_before, "the runs of the held-out points do not move their predictions")
    check(all(ok[r]["observed_points"] == 8 and ok[r]["validated"] and ok[r]["rmse"] < 0.03 for r in ("ratio_LMB", "ratio_AMB")),
          "on the known function the held-out predictions hold (RMSE LMB {:.4f}, AMB {:.4f})".format(ok["ratio_LMB"]["rmse"], ok["ratio_AMB"]["rmse"]))
    check(next(s_ for s_ in after["surrogates"] if s_["response"] == "ratio_LMB")["trend"] == "linear", "the study's trend is the kriging's")
    write_records(1, 8, offset=0.3)
    off = gs.analyze(held, tmp, permutations=200)["held_out"]["responses"]
    check(not off["ratio_AMB"]["validated"] and not off["ratio_LMB"]["validated"] and abs(off["ratio_AMB"]["bias"] - 0.3) < 0.01,
          f"batch 1's ratios offset by 0.3 from batch 0's: the held-out check fails (AMB's mean error {off['ratio_AMB']['bias']:+.3f}, "
          f"Q2 LMB {off['ratio_LMB']['q2']:.2f}, AMB {off['ratio_AMB']['q2']:.2f})")

# The box's corners as a batch of their own ("corners"): the half fraction's points satisfy I = +ABCD and any three of
# the four factors see all eight of their corners, the others stand at their middle; the corners are predicted from
# the points below fitted_on_points_below before they run (the batch-K check leaves them out), the runs do not move
# the predictions, the known function's corners hold and an offset of 0.6 there fails.
four = ["friction", "groove_start_mm", "crack_reach_mm", "E_MPa"]
half = dict(study, batch_points=24, corners={"batch": 2, "factors": four, "half_fraction": True, "fitted_on_points_below": 36})
units = gs.corner_units(half)
index = {f["name"]: i for i, f in enumerate(half["factors"])}
coded = [[2 * u[index[name]] - 1 for name in four] for u in units]
check(len(units) == 8 and all(c[0] * c[1] * c[2] * c[3] == 1 for c in coded), "the half fraction: 8 corners, each with I = +ABCD")
from itertools import combinations  # noqa: E402
check(all(len({tuple(c[i] for i in trio) for c in coded}) == 8 for trio in combinations(range(4), 3)),
      "any three of the four factors see all eight of their corners")
check(all(u[i] == 0.5 for u in units for f, i in index.items() if f not in four), "the other factors stand at their middle")
full = dict(half, corners=dict(half["corners"], half_fraction=False))
check(len(gs.corner_units(full)) == 16 and len({tuple(u) for u in gs.corner_units(full)}) == 16, "the whole factorial: 16 distinct corners")
corner_cases = gs.batch_cases(half, 2)
first_case = corner_cases[0][2]
check(corner_cases[0][0] == 48 and len(corner_cases) == 8 * len(half["needles"])
      and first_case["tissue.friction"] == 0.05 and first_case["needle.groove_start_mm"] == 3.0
      and first_case["cannula.outer_diameter_mm"] == 1.27,
      f"the corner batch holds points 48..55, each factor at a range's end or its middle ({first_case['cannula.outer_diameter_mm']})")
check(gs.batch_cases(half, 1) == gs.batch_cases(dict(half, corners=None), 1), "the Sobol' batches are not moved by the corners")

with tempfile.TemporaryDirectory() as tmp:
    half = dict(half, kriging_trend="linear", held_out={"from_batch": 1})

    def write_corner_records(batch, points_limit=None, offset=0.0):
        write_truth_records(half, tmp, batch, points_limit, offset)

    write_corner_records(0)
    write_corner_records(1, 12)
    gs.write_batch(half, tmp, 2)
    before = gs.analyze(half, tmp, permutations=200)
    corners_before = before["corners_held_out"]
    check(corners_before["fitted_points"] == 36 and corners_before["points"] == list(range(48, 56))
          and corners_before["responses"]["ratio_AMB"]["observed_points"] == 0,
          "the corners are predicted from the 36 points below 36 before they run")
    check(before["held_out"]["points"] == list(range(24, 48)), "batch 1's check leaves the corners to their own")
    predicted_before = stored_predictions(tmp, "corners_held_out")
    write_corner_records(1)  # the rest of batch 1 (points 36-47): at or above the bound, so outside the corners' fit
    write_corner_records(2)
    after = gs.analyze(half, tmp, permutations=200)
    check(stored_predictions(tmp, "corners_held_out") == predicted_before,
          "neither the corners' runs nor batch 1's later points move the corners' predictions")
    ok = after["corners_held_out"]["responses"]
    check(all(ok[r]["observed_points"] == 8 and ok[r]["validated"] for r in ("ratio_LMB", "ratio_AMB")),
          "on the known function the corners' predictions hold (RMSE LMB {:.4f}, AMB {:.4f})".format(ok["ratio_LMB"]["rmse"], ok["ratio_AMB"]["rmse"]))
    check(after["points_complete"] == 56, f"the corners then join the fit ({after['points_complete']} points)")
    write_corner_records(2, offset=0.6)  # the corners spread widely, so Q2 over them forgives a smaller offset
    off = gs.analyze(half, tmp, permutations=200)["corners_held_out"]["responses"]
    check(not off["ratio_AMB"]["validated"] and abs(off["ratio_AMB"]["bias"] - 0.6) < 0.02,
          f"the corners offset by 0.6: their check fails (AMB's mean error {off['ratio_AMB']['bias']:+.3f}, Q2 {off['ratio_AMB']['q2']:.2f})")

# A second held-out round ("points_held_out": {"points": [36, 44]}): the surrogates refitted on every complete point
# outside 36..43 (batch 0, batch 1's first 12 and the corners: 44) predict batch 1's next 8 points before they run; their
# runs do not move the predictions (the fit leaves them out), the known function's points hold, and batch 1's runs
# offset by 0.3 (its 12 fitted points too, so the fit moves by part of it) fail the check.
with tempfile.TemporaryDirectory() as tmp:
    later = dict(half, points_held_out={"points": [36, 44]})  # half: the linear trend and batch 1 held out, as above

    def write_later_records(batch, points_limit=None, offset=0.0):
        write_truth_records(later, tmp, batch, points_limit, offset)

    write_later_records(0)
    write_later_records(1, 12)
    write_later_records(2)
    gs.write_batch(later, tmp, 1, "", 20)
    before = gs.analyze(later, tmp, permutations=200)["points_held_out"]
    check(before["fitted_points"] == 44 and before["points"] == list(range(36, 44))
          and before["responses"]["ratio_AMB"]["observed_points"] == 0,
          f"points 36..43 are predicted from the 44 other complete points before they run ({before['fitted_points']})")
    predicted_before = stored_predictions(tmp, "points_held_out")
    write_later_records(1, 20)
    after = gs.analyze(later, tmp, permutations=200)
    check(stored_predictions(tmp, "points_held_out") == predicted_before, "the held-out points' runs do not move their predictions")
    ok = after["points_held_out"]["responses"]
    check(all(ok[r]["observed_points"] == 8 and ok[r]["validated"] for r in ("ratio_LMB", "ratio_AMB")),
          "on the known function the refitted surrogates' predictions hold (RMSE LMB {:.4f}, AMB {:.4f})".format(ok["ratio_LMB"]["rmse"], ok["ratio_AMB"]["rmse"]))
    check(after["points_complete"] == 52 and after["corners_held_out"]["fitted_points"] == 36,
          f"the points then join the fit, and the corners' own check is not moved ({after['points_complete']} points)")
    write_later_records(1, 20, offset=0.3)
    off = gs.analyze(later, tmp, permutations=200)["points_held_out"]["responses"]
    check(not off["ratio_AMB"]["validated"] and not off["ratio_LMB"]["validated"],
          f"batch 1 offset by 0.3: the check fails (AMB's mean error {off['ratio_AMB']['bias']:+.3f}, Q2 {off['ratio_AMB']['q2']:.2f})")
    for held, words in (({"points": [44, 36]}, "0 <= a < b"), ({"points": 36}, "'points': [a, b]"), ([36, 44], "'points': [a, b]")):
        try:
            gs.read_points_held_out({"points_held_out": held}, "study.json")
            check(False, f"a bad 'points_held_out' is refused ({held})")
        except gs.StudyError as e:
            check(words in str(e), f"a bad 'points_held_out' is refused ({e})")

# One more parameter fitted honestly (second_parameter.py): ratios linear in the value, so every fit has a closed form.
import second_parameter as sp  # noqa: E402

def linear_ratios(amb_offset):
    out = {}
    for v in (3.0, 4.0, 5.0, 6.0):
        out[v] = {"LMB": 0.15 / -1.14 + 0.2 * (v - 5),
                  "AMB": 0.24 / -1.14 + amb_offset + 0.3 * (v - 5), "HMB": 1.71 / -1.14 + 0.1 * (v - 5), "delta_SB_mm": -1.14}
    return out

exact = sp.analyse("needle.groove_start_mm", linear_ratios(0.0))
check(all(abs(h["value"] - 5.0) < 0.01 and abs(h["error_mm"]) < 0.01 for h in exact["leave_one_out"]),
      "second parameter: where one value fits every needle, each held-out needle is predicted at that value with no error")
shifted = sp.analyse("needle.groove_start_mm", linear_ratios(-0.2))
amb_only = next(s_ for s_ in shifted["fitted_on_one"] if s_["fitted_on"] == "AMB")
check(abs(amb_only["value"] - (5.0 + 0.2 / 0.3)) < 0.01 and abs(amb_only["errors_mm"]["AMB"]) < 0.005,
      f"second parameter: fitted on AMB alone, the value solves AMB's ratio ({amb_only['value']:.4f} against {5.0 + 0.2 / 0.3:.4f})")
held_amb = next(h for h in shifted["leave_one_out"] if h["held_out"] == "AMB")
check(abs(held_amb["value"] - 5.0) < 0.01 and abs(held_amb["error_mm"] - (-1.14 * -0.2)) < 0.01,
      f"second parameter: AMB held out is predicted from the value LMB and HMB fit, its error the offset's ({held_amb['error_mm']:+.3f} mm)")
# Replicas (--replica-runs): each lattice's ratios, then their mean; a value one lattice lacks is left out.
lattice_a, lattice_b = linear_ratios(0.1), linear_ratios(-0.1)
del lattice_b[6.0]
both = sp.mean_ratios([lattice_a, lattice_b])
check(sorted(both) == [3.0, 4.0, 5.0] and all(abs(both[v]["AMB"] - linear_ratios(0.0)[v]["AMB"]) < 1e-12 for v in both)
      and all(both[v]["LMB"] == linear_ratios(0.0)[v]["LMB"] for v in both),
      "second parameter: two lattices' ratios averaged, value by value, where both have it")
with tempfile.TemporaryDirectory() as tmp:
    path = os.path.join(tmp, "sweep.json")
    with open(path, "w") as f:
        json.dump(sp.sweep_file("needle.groove_start_mm", [3.0, 5.0], 30.0), f)
    count = subprocess.run([needle, "sweep", path, "--count"], capture_output=True, text=True)
    check(count.returncode == 0 and count.stdout.strip() == "8", f"second parameter: its sweep file passes needle sweep --count ({count.stdout.strip()})")

# A depth into the lip (--lip-depth): each needle's own values, its run with the key unset standing for it from its lip on.
D = sp.DEFAULT
lip_deltas = {"SB": {D: -1.14},
              "LMB": {0.1: 0.40, D: 0.10},                      # lip 0.21: 0.10 from 0.21 on
              "AMB": {0.1: 1.00, 0.3: 0.50, D: 0.20},           # lip 0.43
              "HMB": {0.2: 1.71 + 3 * 0.25, 0.4: 1.71 + 3 * 0.05, 0.6: 1.71 - 3 * 0.15, D: 1.71 - 3 * 0.35}}  # lip 0.8
lips = {"SB": 0.0, "LMB": 0.21, "AMB": 0.43, "HMB": 0.8}
lr = sp.ratios_from(lip_deltas, lips, lip_depth=True)
check(min(lr) == 0.2 and max(lr) == 0.8, f"lip depth: the values analysed are where every needle is known, 0.2 to HMB's lip ({min(lr)}, {max(lr)})")
check(abs(lr[0.6]["AMB"] * -1.14 - 0.20) < 1e-12 and abs(lr[0.43]["AMB"] * -1.14 - 0.20) < 1e-12,
      "lip depth: from its lip's thickness on, a needle is its run with the key unset")
check(abs(lr[0.2]["LMB"] * -1.14 - (0.40 + (0.10 - 0.40) * 0.1 / 0.11)) < 1e-12,
      "lip depth: between its last value and its lip, a needle is interpolated towards its unset run")
lip_fit = sp.analyse("tissue.contact.lip_release_depth_mm", lr)
hmb_only = next(s_ for s_ in lip_fit["fitted_on_one"] if s_["fitted_on"] == "HMB")
check(abs(hmb_only["value"] - 0.45) < 0.002 and abs(hmb_only["errors_mm"]["AMB"] - (0.20 - 0.24)) < 1e-9,
      f"lip depth: fitted on HMB alone the depth solves HMB's line ({hmb_only['value']:.4f} against 0.45), AMB is its unset run")
with tempfile.TemporaryDirectory() as tmp:
    path = os.path.join(tmp, "sweep.json")
    with open(path, "w") as f:
        json.dump(sp.sweep_file("tissue.contact.lip_release_depth_mm", [], 30.0, {"HMB": [0.2, 0.4], "AMB": [0.1]}, True), f)
    unset_cases = [c for c in sp.sweep_file("tissue.contact.lip_release_depth_mm", [], 30.0, {"HMB": [0.2]}, True)["design"]["cases"]
                   if c["label"].endswith(" HMB") and sp.DEFAULT in c["label"]]
    check(len(unset_cases) == 1 and unset_cases[0]["tissue.contact.lip_release_depth_mm"] == "whole lip",
          "lip depth: the run standing for the whole lip says so, not the scene's default depth")
    count = subprocess.run([needle, "sweep", path, "--count"], capture_output=True, text=True)
    check(count.returncode == 0 and count.stdout.strip() == "7",
          f"lip depth: each needle's own values and the four unset runs pass needle sweep --count ({count.stdout.strip()})")
    script = os.path.join(source, "studies", "sensitivity", "second_parameter.py")
    r = subprocess.run([sys.executable, script, "--key", "tissue.contact.lip_release_depth_mm", "--needle-values", "HMB=0.2,0.4",
                        "--out", os.path.join(tmp, "o")], capture_output=True, text=True)
    check(r.returncode == 2 and "--lip-depth" in r.stderr and not os.path.exists(os.path.join(tmp, "o")),
          f"per-needle values without --lip-depth are refused, nothing written ({r.stderr.strip()})")
    r = subprocess.run([sys.executable, script, "--key", "tissue.friction", "--values", "0.1,0.2", "--replica-runs", tmp,
                        "--out", os.path.join(tmp, "o")], capture_output=True, text=True)
    check(r.returncode == 2 and "--analyze-only" in r.stderr and not os.path.exists(os.path.join(tmp, "o")),
          f"--replica-runs without --analyze-only is refused, nothing written ({r.stderr.strip()})")

# Bad study files.
with tempfile.TemporaryDirectory() as tmp:
    bad = os.path.join(tmp, "bad.json")
    with open(bad, "w") as f:
        json.dump({"needles": ["LMB"], "factors": [], "batch_points": 4}, f)
    script = os.path.join(source, "studies", "sensitivity", "global_sensitivity.py")
    r = subprocess.run([sys.executable, script, "--study", bad, "--out", os.path.join(tmp, "o"), "--design-only"], capture_output=True, text=True)
    check(r.returncode == 2 and r.stderr.count("\n") == 1 and "SB" in r.stderr and not os.path.exists(os.path.join(tmp, "o")),
          f"a study without SB is refused with one line, exit 2, nothing written ({r.stderr.strip()})")
    with open(bad, "w") as f:
        json.dump({"needles": ["SB"], "factors": [{"name": "a", "key": "tissue.friction", "range": [0.3, 0.1]}], "batch_points": 4}, f)
    r = subprocess.run([sys.executable, script, "--study", bad, "--out", os.path.join(tmp, "o"), "--design-only"], capture_output=True, text=True)
    check(r.returncode == 2 and "lo < hi" in r.stderr, f"an empty range is refused ({r.stderr.strip()})")

    with open(bad, "w") as f:
        json.dump({"needles": ["SB"], "factors": [{"name": "a", "key": "tissue.friction", "range": [0.1, 0.3]}], "batch_points": 4,
                   "replicas": [{"name": "f", "set": {"tissue.friction": 0.2}}]}, f)
    r = subprocess.run([sys.executable, script, "--study", bad, "--out", os.path.join(tmp, "o"), "--design-only"], capture_output=True, text=True)
    check(r.returncode == 2 and "tissue.friction" in r.stderr and not os.path.exists(os.path.join(tmp, "o")),
          f"a replica that moves a factor is refused ({r.stderr.strip()})")
    with open(bad, "w") as f:
        json.dump({"needles": ["SB"], "factors": [{"name": "a", "key": "tissue.friction", "range": [0.1, 0.3]}], "batch_points": 4,
                   "kriging_trend": "quadratic"}, f)
    r = subprocess.run([sys.executable, script, "--study", bad, "--out", os.path.join(tmp, "o"), "--design-only"], capture_output=True, text=True)
    check(r.returncode == 2 and "kriging_trend" in r.stderr and not os.path.exists(os.path.join(tmp, "o")),
          f"an unknown kriging trend is refused ({r.stderr.strip()})")
    with open(bad, "w") as f:
        json.dump({"needles": ["SB"], "factors": [{"name": "a", "key": "tissue.friction", "range": [0.1, 0.3]}], "batch_points": 4}, f)
    r = subprocess.run([sys.executable, script, "--study", bad, "--out", os.path.join(tmp, "o"), "--design-only", "--points", "5"],
                       capture_output=True, text=True)
    check(r.returncode == 2 and "--points" in r.stderr and not os.path.exists(os.path.join(tmp, "o")),
          f"--points beyond a batch is refused ({r.stderr.strip()})")

    bad_corners = os.path.join(tmp, "bad_corners.json")
    for corners, words in (({"batch": 0, "factors": ["a", "b"], "fitted_on_points_below": 4}, "'batch' of at least 1"),
                           ({"batch": 1, "factors": ["a", "z"], "fitted_on_points_below": 4}, "'z', not a factor"),
                           ({"batch": 1, "factors": ["a", "c"], "fitted_on_points_below": 4}, "a factor of levels"),
                           ({"batch": 1, "factors": ["a", "b", "d"], "fitted_on_points_below": 4}, "more than a batch's 4"),
                           ({"batch": 1, "factors": ["a", "b"]}, "fitted_on_points_below")):
        with open(bad_corners, "w") as f:
            json.dump({"needles": ["SB"], "batch_points": 4, "corners": corners,
                       "factors": [{"name": "a", "key": "tissue.friction", "range": [0.1, 0.3]},
                                   {"name": "b", "key": "needle.groove_start_mm", "range": [3, 6]},
                                   {"name": "c", "key": "tissue.separation.needle_cut", "levels": [True, False]},
                                   {"name": "d", "key": "tissue.contact.crack_reach_mm", "range": [0, 1]}]}, f)
        r = subprocess.run([sys.executable, script, "--study", bad_corners, "--out", os.path.join(tmp, "o"), "--design-only"], capture_output=True, text=True)
        check(r.returncode == 2 and words in r.stderr and not os.path.exists(os.path.join(tmp, "o")),
              f"a bad 'corners' is refused ({r.stderr.strip()})")

    # --allow-other-code reaches `needle sweep` (a stand-in needle records its arguments and fails, so nothing runs).
    fake = os.path.join(tmp, "fake_needle")
    with open(fake, "w") as f:
        f.write("#!/bin/sh\necho \"$@\" >> \"$(dirname \"$0\")/fake_args.txt\"\nexit 2\n")
    os.chmod(fake, 0o755)
    r = subprocess.run([sys.executable, script, "--study", bad, "--out", os.path.join(tmp, "p"), "--needle", fake, "--allow-other-code"],
                       capture_output=True, text=True)
    with open(os.path.join(tmp, "fake_args.txt")) as f:
        fake_args = f.read()
    check(r.returncode == 2 and fake_args.startswith("sweep ") and "--allow-other-code" in fake_args,
          f"--allow-other-code is passed to needle sweep ({fake_args.strip()})")

# --batch K runs that batch alone (the corner batch beside a partial one): the stand-in needle sees batch 2's sweeps only.
with tempfile.TemporaryDirectory() as tmp:
    fake = os.path.join(tmp, "fake_needle")
    with open(fake, "w") as f:
        f.write("#!/bin/sh\necho \"$@\" >> \"$(dirname \"$0\")/fake_args.txt\"\nexit 2\n")
    os.chmod(fake, 0o755)
    study_file = os.path.join(tmp, "corners.json")
    with open(study_file, "w") as f:
        json.dump(dict(half, replicas=[{"name": "y0.1", "set": {"tissue.offset_y_mm": 0.1}}]), f)
    r = subprocess.run([sys.executable, os.path.join(source, "studies", "sensitivity", "global_sensitivity.py"), "--study", study_file,
                        "--out", os.path.join(tmp, "s"), "--needle", fake, "--batch", "2"], capture_output=True, text=True)
    args_file = os.path.join(tmp, "fake_args.txt")
    swept = [line.split()[1] for line in open(args_file).read().splitlines()] if os.path.exists(args_file) else [r.stderr.strip()]
    check(r.returncode == 2 and swept == [os.path.join(tmp, "s", "batch_2", "sweep.json")] and not os.path.exists(os.path.join(tmp, "s", "batch_0")),
          f"--batch 2 writes and runs batch 2 alone ({swept})")

print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)
