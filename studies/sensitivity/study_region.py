"""A region of a study's box: the analysis of the points whose factors lie within narrower ranges, those ranges then
being the factors' own (`global_sensitivity.py --region FACTOR=LO,HI`).

Why: a response can have regimes. AMB's ratio to SB is a staircase in the crushed depth while its lip is crushed only in
part (a particle row at a time), which no smooth surrogate follows; once the depth passes AMB's lip (0.43 mm) every
run is the same to the last digit in it. A calibration that fixes such a factor (the depth fitted on HMB crushes AMB's
lip whole) asks what the other unknowns can still do within that region, and the region's own surrogates answer it:
the factor, narrowed to where it cannot act on a needle (response_view clips it at the lip), drops out of that
needle's surrogates. The points are the study's own; nothing is run. The held-out checks keep their meaning: each
predicts its points in the region from the region's other points only.
"""
from study_design import StudyError


def parse_region(text, study):
    """'FACTOR=LO,HI' -> (factor name, lo, hi), within the factor's range."""
    name, sep, bounds = text.partition("=")
    factors = {f["name"]: f for f in study["factors"]}
    if not sep or name not in factors:
        raise StudyError(f"--region '{text}': expected FACTOR=LO,HI with FACTOR one of {', '.join(factors)}")
    factor = factors[name]
    if "range" not in factor:
        raise StudyError(f"--region '{text}': {name} has levels, not a range")
    try:
        lo, hi = (float(v) for v in bounds.split(","))
    except ValueError:
        raise StudyError(f"--region '{text}': LO,HI must be two numbers")
    f_lo, f_hi = factor["range"]
    if not (f_lo <= lo < hi <= f_hi):
        raise StudyError(f"--region '{text}': need {f_lo:g} <= LO < HI <= {f_hi:g} ({name}'s range)")
    return name, lo, hi


def region_label(regions):
    """The region's folder suffix and its words: ('crushed_depth_mm_0.43_0.8', 'crushed_depth_mm in [0.43, 0.8]')."""
    return ("_".join(f"{n}_{lo:g}_{hi:g}" for n, lo, hi in regions),
            ", ".join(f"{n} in [{lo:g}, {hi:g}]" for n, lo, hi in regions))


def region_study(study, records, regions):
    """The study with each region factor's range narrowed, and the records of the points within every region range
    (a point's value as designed, within 1e-9 of the bounds)."""
    narrowed = {n: (lo, hi) for n, lo, hi in regions}
    keys = {f["name"]: f["key"] for f in study["factors"]}
    factors = [dict(f, range=list(narrowed[f["name"]])) if f["name"] in narrowed else f for f in study["factors"]]

    def inside(values):
        return all(lo - 1e-9 <= float(values[keys[n]]) <= hi + 1e-9 for n, (lo, hi) in narrowed.items())

    kept = {p: rec for p, rec in records.items() if inside(rec["values"])}
    return dict(study, factors=factors), kept
