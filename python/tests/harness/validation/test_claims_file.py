"""ctest validation.claims_file: reference-data/claims.toml holds C1..C20, each once, with every
field, a quantity the runner knows (granular_shaker.validation.quantities) and the parameters it
needs, a known comparison with a band of the right shape, cases that validation/studies.toml
runs with the solvers the claim needs, and a provenance in the paper; and that
validation/diagnoses.toml names known claims, categories, quantities and cases.

Every quantity has its units declared (quantities.UNITS), since the report shows them beside
the claims' values.

It then checks that the checker itself catches broken files (a missing field, an unknown
quantity, a band of the wrong length, a missing id, a case nobody runs), so that a pass means
something.
"""
import os
import tomllib

import pytest

from granular_shaker.validation import quantities
from granular_shaker.validation.diagnoses import validate_diagnoses

from .. import REPOSITORY as ROOT, edited_copy

VALIDATION = os.path.join(ROOT, "validation")

FIELDS = {"id": str, "statement": str, "paper_value": str, "cases": list, "quantity": str,
          "parameters": dict, "comparison": str, "band": list, "solvers": str,
          "provenance": str}
SOLVERS = {"md": {"md"}, "continuum": {"continuum"}, "both": {"md", "continuum"},
           "md_vs_continuum": {"md", "continuum"}}


def check_one(check, claim, where, errors):
    q = check.get("quantity")
    if q not in quantities.QUANTITIES:
        errors.append(f"{where}: unknown quantity '{q}'")
        return
    params = check.get("parameters", {})
    for name in quantities.REQUIRED_PARAMETERS.get(q, ()):
        if name not in params:
            errors.append(f"{where}: quantity '{q}' needs parameter '{name}'")
    for name in quantities.CASE_PARAMETERS:
        if name in params:
            named = params[name] if isinstance(params[name], list) else [params[name]]
            for case in named:
                if case not in claim.get("cases", []):
                    errors.append(f"{where}: parameter {name} names case '{case}', which is "
                                  "not among the claim's cases")
    comparison = check.get("comparison")
    if comparison not in quantities.BAND_LENGTH:
        errors.append(f"{where}: unknown comparison '{comparison}'")
        return
    band = check.get("band")
    if not isinstance(band, list) or len(band) != quantities.BAND_LENGTH[comparison]:
        errors.append(f"{where}: comparison '{comparison}' needs a band of "
                      f"{quantities.BAND_LENGTH[comparison]} numbers, got {band!r}")
    elif not all(isinstance(b, (int, float)) for b in band):
        errors.append(f"{where}: band {band!r} is not numeric")
    elif comparison in ("range", "all_in_range") and not band[0] < band[1]:
        errors.append(f"{where}: band {band!r} is empty")


def validate(claims, studies):
    errors = []
    runs = {c["name"]: set(c["solvers"]) for c in studies["case"]}
    ids = [c.get("id") for c in claims]
    for n in range(1, 21):
        if ids.count(f"C{n}") != 1:
            errors.append(f"C{n} appears {ids.count(f'C{n}')} times (expected once)")
    extra = [i for i in ids if i not in {f"C{n}" for n in range(1, 21)}]
    if extra:
        errors.append(f"unexpected ids {extra}")
    for claim in claims:
        where = claim.get("id", "?")
        for field, kind in FIELDS.items():
            if field not in claim:
                errors.append(f"{where}: field '{field}' missing")
            elif not isinstance(claim[field], kind):
                errors.append(f"{where}: field '{field}' is not a {kind.__name__}")
            elif kind in (str, list) and not claim[field] and field != "band":
                errors.append(f"{where}: field '{field}' is empty")
        if claim.get("solvers") not in SOLVERS:
            errors.append(f"{where}: solvers must be one of {sorted(SOLVERS)}")
        else:
            for case in claim.get("cases", []):
                if case not in runs:
                    errors.append(f"{where}: case '{case}' is not in validation/studies.toml")
                elif not SOLVERS[claim["solvers"]] <= runs[case]:
                    errors.append(f"{where}: case '{case}' is not run with "
                                  f"{sorted(SOLVERS[claim['solvers']] - runs[case])}")
        provenance = claim.get("provenance", "")
        if "Sec." not in provenance and "Fig." not in provenance:
            errors.append(f"{where}: provenance names no section or figure of the paper")
        if "continuum_gci" in claim and not (
                isinstance(claim["continuum_gci"], str) and claim["continuum_gci"]
                and claim.get("solvers") in ("continuum", "both")
                and claim.get("cases") == ["base"]):
            errors.append(f"{where}: continuum_gci must name a quantity of the base-case grid "
                          "study, for a claim on the base case with a continuum value")
        check_one(claim, claim, where, errors)
        for i, extra_check in enumerate(claim.get("also", [])):
            check_one(extra_check, claim, f"{where} (also #{i + 1})", errors)
    return errors


def broken_copies(claims):
    """(description, broken claims list) pairs the checker must reject."""
    def edit(change):
        return edited_copy(claims, change)
    return [
        ("missing field", edit(lambda c: c[3].pop("provenance"))),
        ("unknown quantity", edit(lambda c: c[0].update(quantity="shock_sped"))),
        ("band of the wrong length", edit(lambda c: c[0].update(band=[0.1]))),
        ("missing id", edit(lambda c: c.pop(19))),
        ("case nobody runs", edit(lambda c: c[0].update(cases=["no_such_case"]))),
        ("missing parameter", edit(lambda c: c[4].update(parameters={}))),
        ("unknown comparison", edit(lambda c: c[1].update(comparison="about"))),
        ("GCI for a claim without one base-case continuum value",
         edit(lambda c: c[16].update(continuum_gci="max_mach"))),
    ]


def broken_diagnoses(diagnoses):
    """(description, broken diagnoses) pairs the diagnoses check must reject."""
    def edit(change):
        return edited_copy(diagnoses, change)
    return [
        ("unknown claim", edit(lambda d: d[0].update(claim="C21"))),
        ("unknown category", edit(lambda d: d[0].update(category="e"))),
        ("no reason", edit(lambda d: d[0].update(reason=" "))),
        ("unknown evidence quantity", edit(lambda d: d[0]["evidence"][0].update(quantity="x"))),
        ("evidence on a case nobody runs",
         edit(lambda d: d[0]["evidence"][0].update(cases=["no_such_case"]))),
        ("evidence missing a parameter",
         edit(lambda d: d[0]["evidence"][1].update(parameters={}))),
    ]


def load_claims_and_studies():
    with open(os.path.join(ROOT, "reference-data", "claims.toml"), "rb") as f:
        claims = tomllib.load(f)["claim"]
    with open(os.path.join(VALIDATION, "studies.toml"), "rb") as f:
        studies = tomllib.load(f)
    return claims, studies


def load_diagnoses():
    with open(os.path.join(VALIDATION, "diagnoses.toml"), "rb") as f:
        return tomllib.load(f)["diagnosis"]


CLAIMS, STUDIES = load_claims_and_studies()
DIAGNOSES = load_diagnoses()


def test_claims_file_is_clean():
    errors = validate(CLAIMS, STUDIES)
    assert errors == [], f"claims.toml: {len(CLAIMS)} claims, {len(errors)} problems"


@pytest.mark.parametrize("description, broken", broken_copies(CLAIMS),
                         ids=[d for d, _ in broken_copies(CLAIMS)])
def test_broken_claims_are_caught(description, broken):
    assert validate(broken, STUDIES), f"broken copy ({description}) NOT CAUGHT"


def test_diagnoses_file_is_clean():
    """validation/diagnoses.toml is clean, and its checker catches broken copies."""
    errors = validate_diagnoses(DIAGNOSES, CLAIMS, STUDIES)
    assert errors == [], f"diagnoses.toml: {len(DIAGNOSES)} diagnoses, {len(errors)} problems"


@pytest.mark.parametrize("description, broken", broken_diagnoses(DIAGNOSES),
                         ids=[d for d, _ in broken_diagnoses(DIAGNOSES)])
def test_broken_diagnoses_are_caught(description, broken):
    assert validate_diagnoses(broken, CLAIMS, STUDIES), \
        f"broken diagnoses ({description}) NOT CAUGHT"


def test_every_quantity_has_units():
    missing = sorted(set(quantities.QUANTITIES) - set(quantities.UNITS))
    assert not missing, f"quantities without units in quantities.UNITS: {missing}"
    stray = sorted(set(quantities.UNITS) - set(quantities.QUANTITIES))
    assert not stray, f"quantities.UNITS names quantities that do not exist: {stray}"
    blank = sorted(q for q, units in quantities.UNITS.items()
                   if not isinstance(units, str) or not units.strip())
    assert not blank, f"quantities with blank units: {blank}"
