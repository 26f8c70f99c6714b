"""The global sensitivity study's statistics (studies/sensitivity/global_sensitivity.py), all OpenTURNS's: HSIC
indices with permutation p-values, kriging surrogates that take the runs' noise and are validated by leave-one-out, an
additive polynomial chaos with its Sobol' indices, and the joint search of the box for the point nearest the
experiment."""
import math
import statistics

from study_design import numeric, unit_coordinate, value_at_unit
from study_runs import calibrated_errors, response_view

MIN_Q2 = 0.5  # below it a surrogate does not predict left-out points well enough for its extremes to be claimed
# ... unless the runs themselves scatter: a surrogate that misses a left-out point by no more than this many of the
# replicas' standard deviations predicts it about as well as the same run on a shifted lattice would.
RMSE_OVER_SCATTER = 1.5


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


def data_sd(rows, noise_sd):
    """The noise of the rows' values, given one run's noise_sd: a row that is the mean of k runs carries noise_sd / sqrt(k)
    (root mean square over the rows). None without noise_sd."""
    if not noise_sd:
        return None
    return noise_sd * math.sqrt(sum(1.0 / r.get("runs", 1) for r in rows) / len(rows))


def run_distances(factors, rows, unit_point):
    """How far a point of the box (unit coordinates over `factors`) lies from the nearest run point, and how far the run
    points lie from each other (the median of each one's nearest neighbour), both in unit coordinates: a surrogate's
    value at a point farther from every run than the runs are from each other is an extrapolation, whatever its
    validation on the runs says (the validation's points are the runs' own neighbours)."""
    points = [[unit_coordinate(f, r[f["name"]]) for f in factors] for r in rows]

    def distance(a, b):
        return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))

    nearest = min(distance(unit_point, p) for p in points)
    spacing = statistics.median(min(distance(p, q) for j, q in enumerate(points) if j != i) for i, p in enumerate(points)) \
        if len(points) >= 2 else float("nan")
    return {"nearest_run": nearest, "run_spacing": spacing, "extrapolated": nearest > spacing}


def surrogate_validated(q2, rmse, scatter_sd):
    """A surrogate is validated when it predicts left-out points (Q2 >= MIN_Q2), or misses them by no more than
    RMSE_OVER_SCATTER of the runs' own scatter (then the response's spread over the box is mostly that scatter)."""
    return q2 >= MIN_Q2 or (scatter_sd is not None and scatter_sd > 0 and rmse <= RMSE_OVER_SCATTER * scatter_sd)


def fit_kriging(study, rows, response, factor_names, noise_sd=None):
    """A kriging surrogate of the response on the named factors (the study's "kriging_trend": a constant, the default, or
    linear in the factors; squared-exponential ARD; each factor scaled to [0, 1] over its range) and its leave-one-out Q2
    and RMSE: (model, factors, q2, rmse, kriging result). With noise_sd (the
    runs' own scatter, one run's), each row is taken as the response plus that noise, divided by the square root of
    the runs it averages: the surrogate smooths rather than interpolates, and its extremes are those of the response,
    not of one run's rounding. Leave-one-out leaves a whole point out, all its runs."""
    import openturns as ot
    ot.Log.Show(ot.Log.NONE)  # OpenTURNS warns each time it narrows the correlation lengths' bounds to the data
    factors = [f for f in study["factors"] if f["name"] in factor_names]
    x = ot.Sample([[unit_coordinate(f, r[f["name"]]) for f in factors] for r in rows])
    y = ot.Sample([[r[response]] for r in rows])
    dim = len(factors)
    variances = [noise_sd * noise_sd / r.get("runs", 1) for r in rows] if noise_sd else None

    linear = study.get("kriging_trend", "constant") == "linear"

    def fit(keep):
        basis = (ot.LinearBasisFactory if linear else ot.ConstantBasisFactory)(dim).build()
        algo = ot.KrigingAlgorithm(x[keep], y[keep], ot.SquaredExponential([0.5] * dim, [1.0]), basis)
        algo.setOptimizationBounds(ot.Interval([0.05] * dim, [10.0] * dim))
        if variances:
            algo.setNoise([variances[i] for i in keep])
        algo.run()
        return algo.getResult()

    n = x.getSize()
    errors = []
    for k in range(n):
        keep = [i for i in range(n) if i != k]
        errors.append(fit(keep).getMetaModel()(x[k])[0] - y[k][0])
    mean = y.computeMean()[0]
    variance = sum((y[i][0] - mean) ** 2 for i in range(n)) / n
    press = sum(e * e for e in errors) / n
    q2 = 1.0 - press / variance if variance > 0 else float("nan")
    result = fit(list(range(n)))
    return result.getMetaModel(), factors, q2, math.sqrt(press), result


def pce_sobol(study, rows, response, degree=2):
    """A sparse additive polynomial chaos of the response over every factor (Legendre polynomials of each factor scaled to
    [0, 1] up to `degree`, no interaction terms, the terms chosen by LARS with corrected leave-one-out), its leave-one-out Q2 (refitted without
    each point), and the first-order and total Sobol' indices it gives: {factor: (first, total)}."""
    import openturns as ot
    ot.Log.Show(ot.Log.NONE)
    factors = study["factors"]
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
            "validated": q2 >= MIN_Q2,
            "box_min": {"value": values[k_min][0], "at": at(k_min), **run_distances(factors, rows, list(grid[k_min]))},
            "box_max": {"value": values[k_max][0], "at": at(k_max), **run_distances(factors, rows, list(grid[k_max]))}}


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
    model, factors, q2, rmse, _ = fit_kriging(study, rows, response, factor_names, noise_sd)
    grid = box_grid(factors)
    values = model(grid)

    def at(k):
        return {f["name"]: value_at_unit(f, float(grid[k, j])) for j, f in enumerate(factors)}

    k_min = min(range(grid.getSize()), key=lambda i: values[i][0])
    k_max = max(range(grid.getSize()), key=lambda i: values[i][0])
    noise = data_sd(rows, noise_sd)
    return {"response": response, "factors": [f["name"] for f in factors], "points": len(rows),
            "trend": study.get("kriging_trend", "constant"),
            "leave_one_out_q2": q2, "leave_one_out_rmse": rmse, "replica_sd": noise_sd, "data_sd": noise,
            "validated": surrogate_validated(q2, rmse, noise),
            "box_min": {"value": values[k_min][0], "at": at(k_min), **run_distances(factors, rows, list(grid[k_min]))},
            "box_max": {"value": values[k_max][0], "at": at(k_max), **run_distances(factors, rows, list(grid[k_max]))},
            "observed_min": min(r[response] for r in rows), "observed_max": max(r[response] for r in rows)}


def joint_search(study, rows, factor_names, scatter=None, own_factors=None):
    """The point of the box (the named factors; the others averaged out) whose surrogate ratios, calibrated on SB, come
    nearest the experiment: the largest |error| over the multi-bevel needles is the smallest. With own_factors
    ({needle: names}), each ratio's kriging takes its own factors (those of its surrogate in the tables, so that the
    search is made of the surrogates validated there); else every ratio takes all the named factors."""
    import openturns as ot
    scatter = scatter or {}
    needles = [n for n in study["needles"] if n != "SB"]
    factors = [f for f in study["factors"] if f["name"] in factor_names]
    grid = box_grid(factors, 8192)
    fits, values = {}, {}
    for n in needles:
        # Each ratio's kriging sees the study as that ratio does (a factor within the lip clipped at the needle's lip, or
        # left out): the box's points are mapped to its own coordinates.
        view_study, view_rows = response_view(study, rows, f"ratio_{n}")
        own = [f for f in view_study["factors"] if f["name"] in (own_factors[n] if own_factors else factor_names)]
        fits[n] = fit_kriging(view_study, view_rows, f"ratio_{n}", [f["name"] for f in own], scatter.get(f"ratio_{n}"))
        names = [g["name"] for g in factors]
        columns = [(names.index(f["name"]), f) for f in own]
        mapped = ot.Sample(grid.getSize(), len(own))
        for i in range(grid.getSize()):
            for k, (j, f) in enumerate(columns):
                value = value_at_unit(factors[j], float(grid[i, j]))
                if "range" in f:
                    value = min(max(value, f["range"][0]), f["range"][1])
                mapped[i, k] = unit_coordinate(f, value)
        values[n] = fits[n][0](mapped)
    best, best_score = 0, float("inf")
    for i in range(grid.getSize()):
        score = max(abs(e) for e in calibrated_errors({n: values[n][i][0] for n in needles}).values())
        if score < best_score:
            best, best_score = i, score
    ratios = {n: values[n][best][0] for n in needles}
    return {"factors": [f["name"] for f in factors],
            "leave_one_out_q2": {n: fits[n][2] for n in needles}, "leave_one_out_rmse": {n: fits[n][3] for n in needles},
            "validated": all(surrogate_validated(fits[n][2], fits[n][3], data_sd(rows, scatter.get(f"ratio_{n}"))) for n in needles),
            "best_at": {f["name"]: value_at_unit(f, float(grid[best, j])) for j, f in enumerate(factors)},
            "best_ratios": ratios, "best_calibrated_errors_mm": calibrated_errors(ratios), "best_max_error_mm": best_score,
            "best_distance": run_distances(factors, rows, list(grid[best]))}
