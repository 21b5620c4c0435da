"""Diagnoses of failing claims (validation/diagnoses.toml): each names its claim, a category
and a reason, and the evidence the study measures for it."""
from granular_shaker.validation import quantities
from granular_shaker.validation.claims import measure
from granular_shaker.validation.plan import SOLVERS, load_toml


CATEGORIES = {"a": "the continuum and MD really differ",
              "b": "MD does not reproduce the paper's statement",
              "c": "a defect of the project still to find or fix",
              "d": "the continuum's equations give it, whatever the numerical choices"}


def validate_diagnoses(diagnoses, claims, studies):
    """Problems of validation/diagnoses.toml: a claim id (or 'Fig. N') the claims file has, a
    category a/b/c, a reason, and evidence of known quantities with the parameters they need,
    on cases validation/studies.toml runs with the solvers named."""
    errors = []
    ids = {c["id"] for c in claims}
    runs = {c["name"]: set(c["solvers"]) for c in studies["case"]}
    for d in diagnoses:
        where = f"diagnosis of {d.get('claim')}"
        if d.get("claim") not in ids and not str(d.get("claim", "")).startswith("Fig. "):
            errors.append(f"{where}: no such claim (allowed: C1 .. C20 or 'Fig. N')")
        if d.get("category") not in CATEGORIES:
            errors.append(f"{where}: category must be one of {', '.join(CATEGORIES)}")
        if not str(d.get("reason", "")).strip():
            errors.append(f"{where}: no reason")
        for item in d.get("evidence", []):
            q = item.get("quantity")
            if q not in quantities.QUANTITIES:
                errors.append(f"{where}: unknown quantity {q!r}")
                continue
            missing = [n for n in quantities.REQUIRED_PARAMETERS.get(q, ())
                       if n not in item.get("parameters", {})]
            if missing:
                errors.append(f"{where}: quantity {q!r} needs parameter(s) {missing}")
            solvers = {s for s in item.get("solvers", SOLVERS) if s != "md_vs_continuum"}
            for case in item.get("cases", []):
                if case not in runs:
                    errors.append(f"{where}: case {case!r} is not in validation/studies.toml")
                elif "solvers" in item and not solvers <= runs[case]:
                    errors.append(f"{where}: case {case!r} is not run with "
                                  f"{sorted(solvers - runs[case])}")
            if not item.get("cases"):
                errors.append(f"{where}: evidence {item.get('label')!r} names no case")
    return errors


def load_diagnoses(path, claims, studies):
    """validation/diagnoses.toml; raises ValueError naming every problem."""
    diagnoses = load_toml(path).get("diagnosis", [])
    errors = validate_diagnoses(diagnoses, claims, studies)
    if errors:
        raise ValueError(f"{path}: " + "; ".join(errors))
    return diagnoses


def evidence_solvers(item, views):
    if "solvers" in item:
        return item["solvers"]
    return [s for s in SOLVERS if any((c, s) in views for c in item["cases"])]


def diagnose(diagnoses, results, views, comparer, partial_cases_ok):
    """Measures the evidence of every diagnosis and ties it to its claim's status: a
    diagnosis of a claim that no longer fails is marked stale; a failing claim without one is
    listed as undiagnosed."""
    status = {c["id"]: c["status"] for c in results}
    out = []
    for d in diagnoses:
        evidence = []
        for item in d.get("evidence", []):
            measured = {s: measure(item["quantity"], item.get("parameters", {}), item["cases"], s,
                                   views, comparer, partial_cases_ok)
                        for s in evidence_solvers(item, views)}
            evidence.append(dict(label=item["label"], quantity=item["quantity"],
                                 units=quantities.UNITS[item["quantity"]], measured=measured))
        claim_status = status.get(d["claim"])
        out.append(dict(d, evidence=evidence, claim_status=claim_status,
                        stale=claim_status is not None and claim_status != "fail"))
    diagnosed = {d["claim"] for d in diagnoses}
    undiagnosed = [c["id"] for c in results if c["status"] == "fail" and c["id"] not in diagnosed]
    return out, undiagnosed
