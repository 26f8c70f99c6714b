"""The global sensitivity study's design (studies/sensitivity/global_sensitivity.py): the study file, its factors and
replicas, the Sobol' points of each batch, and each batch's sweep file for `needle sweep`."""
import json
import os
import re


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
        if f.get("acts_within_lip") and "range" not in f:
            raise StudyError(f"{path}: factor '{f['name']}': 'acts_within_lip' needs a 'range' (a depth in mm)")
    if not (isinstance(study["batch_points"], int) and study["batch_points"] >= 2):
        raise StudyError(f"{path}: 'batch_points' must be an integer of at least 2")
    if study.get("kriging_trend", "constant") not in ("constant", "linear"):
        raise StudyError(f"{path}: 'kriging_trend' must be \"constant\" or \"linear\"")
    read_corners(study, path)
    read_points_held_out(study, path)
    held = study.get("held_out")
    if held is not None and not (isinstance(held, dict) and isinstance(held.get("from_batch"), int) and held["from_batch"] >= 1):
        raise StudyError(f"{path}: 'held_out' needs a 'from_batch' of at least 1 (the surrogates are fitted on the batches before it)")
    factor_keys = {f["key"] for f in study["factors"]}
    replica_names = set()
    for r in study.get("replicas", []):
        if not isinstance(r, dict) or not isinstance(r.get("name"), str) or not re.fullmatch(r"[A-Za-z0-9.+_-]+", r["name"]):
            raise StudyError(f"{path}: each replica needs a 'name' of letters, digits and . + _ - (it names a folder)")
        if r["name"] in replica_names:
            raise StudyError(f"{path}: replica '{r['name']}' appears twice")
        replica_names.add(r["name"])
        if not isinstance(r.get("set"), dict) or not r["set"]:
            raise StudyError(f"{path}: replica '{r['name']}' needs a 'set' of scene keys")
        moved = sorted(factor_keys & set(r["set"]))
        if moved:
            raise StudyError(f"{path}: replica '{r['name']}' sets {moved[0]}, a factor of the study: a replica repeats the design, it does not move it")
    return study


def read_corners(study, path):
    """A study file's "corners": {"batch": K, "factors": [names], "half_fraction": bool, "fitted_on_points_below": N}:
    batch K is not the Sobol' sequence's next points but the corners of the box of the named factors (each at its
    range's ends, every other factor at its range's middle), the whole 2^k factorial or, with "half_fraction", the half
    whose last factor's end is the product of the others' (coded -1/+1, I = +AB..K: any k-1 of the factors see every
    one of their corners). A surrogate's reach lies at the box's corners, where a Sobol' design of a few dozen points
    has no run; the corners are predicted from the points below N before they run (study_held_out.py) and then join
    the fit."""
    corners = study.get("corners")
    if corners is None:
        return
    if not isinstance(corners, dict):
        raise StudyError(f"{path}: 'corners' must be an object")
    batch = corners.get("batch")
    if not (isinstance(batch, int) and not isinstance(batch, bool) and batch >= 1):
        raise StudyError(f"{path}: 'corners' needs a 'batch' of at least 1 (the Sobol' batches before it are the points it is predicted from)")
    names = corners.get("factors")
    by_name = {f["name"]: f for f in study["factors"]}
    if not (isinstance(names, list) and len(names) >= 2 and len(set(names)) == len(names)):
        raise StudyError(f"{path}: 'corners' needs 'factors', at least two distinct factor names")
    for name in names:
        if name not in by_name:
            raise StudyError(f"{path}: 'corners' names '{name}', not a factor of the study")
        if "range" not in by_name[name]:
            raise StudyError(f"{path}: 'corners' names '{name}', a factor of levels: a corner is a range's end")
    if not isinstance(corners.get("half_fraction", False), bool):
        raise StudyError(f"{path}: 'corners': 'half_fraction' is true or false")
    count = len(corner_units(study, corners))
    if count > study["batch_points"]:
        raise StudyError(f"{path}: 'corners' makes {count} points, more than a batch's {study['batch_points']} (batch_points)")
    below = corners.get("fitted_on_points_below")
    if not (isinstance(below, int) and not isinstance(below, bool) and 4 <= below <= batch * study["batch_points"]):
        raise StudyError(f"{path}: 'corners' needs 'fitted_on_points_below': the points the predictions are fitted on "
                         f"(at least 4, at most the {batch * study['batch_points']} points of the batches before it)")


def read_points_held_out(study, path):
    """A study file's "points_held_out": {"points": [a, b]}: the design points a..b-1 are predicted by the analysis's
    procedure fitted on every other complete point, before they run (study_held_out.py), a second held-out round for
    surrogates that were refitted after the first."""
    held = study.get("points_held_out")
    if held is None:
        return
    points = held.get("points") if isinstance(held, dict) else None
    if not (isinstance(points, list) and len(points) == 2 and all(isinstance(p, int) and not isinstance(p, bool) for p in points)
            and 0 <= points[0] < points[1]):
        raise StudyError(f"{path}: 'points_held_out' needs 'points': [a, b], the design points a..b-1 it predicts (0 <= a < b)")


def corner_units(study, corners=None):
    """The corner batch's points in unit coordinates, in standard order (the first factor alternating fastest)."""
    corners = corners if corners is not None else study["corners"]
    names = corners["factors"]
    free = names[:-1] if corners.get("half_fraction") else names
    points = []
    for k in range(2 ** len(free)):
        signs = {name: (1 if (k >> i) & 1 else -1) for i, name in enumerate(free)}
        if corners.get("half_fraction"):
            product = 1
            for v in signs.values():
                product *= v
            signs[names[-1]] = product
        points.append([0.5 if f["name"] not in signs else (1.0 if signs[f["name"]] > 0 else 0.0) for f in study["factors"]])
    return points


def corner_batch(study):
    """The batch of box corners (read_corners), or None."""
    return study["corners"]["batch"] if study.get("corners") else None


def replica_names(study):
    """The design's runs: the plain one (named "") and each replica (the same points run again with the replica's scene
    keys set on top: the lattice shifted, so that each point's own run-to-run scatter is measured)."""
    return [""] + [r["name"] for r in study.get("replicas", [])]


def replica_set(study, name):
    return next(r["set"] for r in study.get("replicas", []) if r["name"] == name) if name else {}


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


def batch_cases(study, batch, points_limit=None):
    """The design points of one batch, each run on every needle: [(point index, needle, {key: value})]; with
    points_limit, only the batch's first points_limit points (a partial batch, which the whole batch later extends)."""
    n = study["batch_points"]
    if batch == corner_batch(study):
        points = corner_units(study)
    else:
        points = unit_design(len(study["factors"]), (batch + 1) * n)[batch * n:]
    if points_limit is not None:
        points = points[:points_limit]
    cases = []
    for k, u in enumerate(points):
        point = batch * n + k
        values = {f["key"]: factor_value(f, uk) for f, uk in zip(study["factors"], u)}
        for needle in study["needles"]:
            cases.append((point, needle, values))
    return cases


def sweep_file(study, batch, replica="", points_limit=None):
    cases = []
    for point, needle, values in batch_cases(study, batch, points_limit):
        case = {"label": f"point {point:03d} {needle}", "needle.preset": needle}
        case.update(values)
        cases.append(case)
    sweep = {"design": {"cases": cases}}
    if study.get("model"):
        sweep["model"] = study["model"]
    fixed = dict(study.get("set", {}))
    fixed.update(replica_set(study, replica))
    if fixed:
        sweep["set"] = fixed
    return sweep


def extends(longer, shorter):
    """Whether the sweep `longer` is `shorter` with more cases after its own (a partial batch completed)."""
    a, b = dict(longer), dict(shorter)
    cases_a, cases_b = a.pop("design")["cases"], b.pop("design")["cases"]
    return a == b and len(cases_a) >= len(cases_b) and cases_a[:len(cases_b)] == cases_b


def write_sweep_file(path, sweep):
    """Writes a study's sweep file whole, or accepts the same one already there (a rerun), or replaces a partial batch's
    by one that extends it (needle sweep then runs only the cases it has not recorded); StudyError for another."""
    text = json.dumps(sweep, indent=1) + "\n"
    if os.path.exists(path):
        with open(path) as f:
            old_text = f.read()
        if old_text == text:
            return path
        old = json.loads(old_text)
        if extends(old, sweep):
            raise StudyError(f"{path} holds more of this batch than asked ({len(old['design']['cases'])} cases): "
                             "run it without --points, or with at least as many")
        if not extends(sweep, old):
            raise StudyError(f"{path} holds another design (the study changed?): give a new --out")
        with open(path + ".tmp", "w") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
    else:
        with open(path + ".tmp", "w") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
    return path


def batch_folder(out, batch, replica=""):
    return os.path.join(out, f"batch_{batch}" + (f"_{replica}" if replica else ""))


def write_batch(study, out, batch, replica="", points_limit=None):
    folder = batch_folder(out, batch, replica)
    os.makedirs(folder, exist_ok=True)
    return write_sweep_file(os.path.join(folder, "sweep.json"), sweep_file(study, batch, replica, points_limit))
