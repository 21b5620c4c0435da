"""The paper's claims (reference-data/claims.toml) evaluated on the views of a study: each
check's value with its uncertainty (the jackknife over MD's samples, rounding of quantised
values) and its verdict against the band."""
import math

import numpy as np

from granular_shaker.validation import quantities
from granular_shaker.validation.plan import SOLVERS


def _spread(kind, values):
    values = [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    if len(values) < 2:
        return math.nan
    values = np.array(values, dtype=float)
    if kind == "jackknife":
        n = len(values)
        return float(math.sqrt((n - 1) / n * np.sum((values - values.mean()) ** 2)))
    return float(values.std(ddof=1))


def _as_plain(value):
    if isinstance(value, (quantities.Bound, quantities.Quantized, quantities.Measured)):
        return _as_plain(value.value)
    return value


def _with_rounding(error, value, resolution):
    """The sampling error combined with the rounding error of a quantised value."""
    def one(e, v, r):
        rounding = r / math.sqrt(12.0) if r is not None and quantities.finite(v) else None
        if rounding is None:
            return e
        return rounding if e is None else math.hypot(e, rounding)
    if resolution is None:
        return error
    if isinstance(value, list):
        errors = error if isinstance(error, list) else [None] * len(value)
        return [one(e, v, r) for e, v, r in zip(errors, value, resolution)]
    return one(error, value, resolution)


def measure(quantity, params, cases, solver, views, comparer, partial_cases_ok):
    """Value and uncertainty of one quantity of the given cases in one solver
    ('md_vs_continuum' for pair quantities): dict(value, error, bound, resolution, notes), or
    dict(value=None, status="not measured", reason)."""
    fn = quantities.QUANTITIES[quantity]

    def query(replicate):
        def get_run(case, s):
            view = views.get((case, s))
            if view is None or view.status != "ok" and quantity != "collapse_detected":
                return None
            if replicate is not None and view.replicates:
                return view.replicates[replicate]
            return view
        return quantities.Query(get_run, comparer, solver, cases, params, partial_cases_ok)

    try:
        value = fn(query(None))
    except quantities.NotMeasured as reason:
        missing = [f"{s} {c}: {views[(c, s)].status}" for c in cases
                   for s in SOLVERS if (c, s) in views and views[(c, s)].status != "ok"]
        return dict(value=None, status="not measured", reason=str(reason)
                    + (f" ({'; '.join(missing)})" if missing else ""))
    bound = value.kind if isinstance(value, quantities.Bound) else None
    resolution = value.resolution if isinstance(value, quantities.Quantized) else None
    direct_error = value.error if isinstance(value, quantities.Measured) else None
    value = _as_plain(value)
    # Uncertainty: the same quantity on every replicate of the MD views involved.
    involved = [v for (c, s), v in views.items() if c in cases and v.replicates
                and (solver in (s, "md_vs_continuum"))]
    error = None
    if involved and isinstance(value, (float, list)):
        count = min(len(v.replicates) for v in involved)
        kind = involved[0].replicate_kind
        reps = []
        for b in range(count):
            try:
                reps.append(_as_plain(fn(query(b))))
            except quantities.NotMeasured:
                pass
        if isinstance(value, float):
            error = _spread(kind, reps)
            error = None if math.isnan(error) else error
        elif reps:
            error = [_spread(kind, [r[i] for r in reps if len(r) == len(value)])
                     for i in range(len(value))]
            error = [None if math.isnan(e) else e for e in error]
    if error is None and quantities.finite(direct_error):
        error = direct_error
    notes = sorted({n for (c, s), v in views.items() if c in cases
                    and solver in (s, "md_vs_continuum") for n in v.notes})
    return dict(value=value, error=_with_rounding(error, value, resolution), bound=bound,
                notes=notes)


def evaluate(check_spec, claim, solver, views, comparer, partial_cases_ok):
    """Value, uncertainty and verdict of one check of a claim in one solver: pass (inside the
    band by more than DECISION_ERRORS standard errors), fail (outside by more), unresolved
    (in between: the data cannot decide), inconclusive (a bound that cannot decide) or not
    measured."""
    m = measure(check_spec["quantity"], check_spec.get("parameters", {}), claim["cases"], solver,
                views, comparer, partial_cases_ok)
    if m.get("status") == "not measured":
        return m
    value, error, bound = m["value"], m["error"], m["bound"]
    passed = quantities.check(check_spec["comparison"], check_spec["band"], value)
    inside = quantities.margin(check_spec["comparison"], check_spec["band"], value, error)
    status = quantities.verdict(inside)
    if bound == "lower" and check_spec["comparison"] == "less_than" and passed:
        status = "inconclusive"
    if bound == "lower" and check_spec["comparison"] == "greater_than" and not passed:
        status = "inconclusive"
    return dict(m, status=status, margin=inside)


# A claim's status is the worst of its checks' statuses, in this order.
STATUS_ORDER = ["fail", "not measured", "unresolved", "inconclusive", "pass"]


def worst_status(statuses):
    statuses = list(statuses)
    return next((s for s in STATUS_ORDER if s in statuses), "pass")


def evaluate_claims(claims, views, comparer, partial_cases_ok):
    results = []
    for claim in claims:
        solvers = (["md", "continuum"] if claim["solvers"] == "both" else [claim["solvers"]])
        checks = [dict(quantity=claim["quantity"], parameters=claim.get("parameters", {}),
                       comparison=claim["comparison"], band=claim["band"])]
        checks += claim.get("also", [])
        # The report shows each check's units beside its values and band.
        checks = [dict(c, units=quantities.UNITS[c["quantity"]]) for c in checks]
        per_solver = {}
        for solver in solvers:
            evaluations = [evaluate(c, claim, solver, views, comparer, partial_cases_ok)
                           for c in checks]
            per_solver[solver] = dict(status=worst_status(e["status"] for e in evaluations),
                                      checks=evaluations)
        overall = worst_status(s["status"] for s in per_solver.values())
        results.append(dict(claim, checks=checks, per_solver=per_solver, status=overall))
    return results


def required_not_passing(results, require, accepted):
    """The entries of a requirement list (ID, or ID:SOLVER for one solver's check of a claim,
    e.g. C1:md) whose status is not among `accepted`, as 'ID (status)' strings; an unknown
    entry counts as failing."""
    failing = []
    for entry in (e.strip() for e in require.split(",") if e.strip()):
        claim_id, _, solver = entry.partition(":")
        claim = next((c for c in results if c["id"] == claim_id), None)
        if claim is None:
            failing.append(f"{entry} (no such claim)")
        elif not solver:
            if claim["status"] not in accepted:
                failing.append(f"{entry} ({claim['status']})")
        elif solver not in claim["per_solver"]:
            failing.append(f"{entry} (not checked for {solver})")
        elif claim["per_solver"][solver]["status"] not in accepted:
            failing.append(f"{entry} ({claim['per_solver'][solver]['status']})")
    return failing


def format_value(value):
    """A check's value for a log line: 4 significant digits, lists in brackets."""
    if isinstance(value, list):
        return "[" + ", ".join("nan" if v is None or math.isnan(v) else f"{v:.4g}"
                               for v in value) + "]"
    if isinstance(value, float):
        return f"{value:.4g}"
    return "-"
