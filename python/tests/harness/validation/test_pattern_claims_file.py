"""ctest validation.pattern_claims_file: reference-data/pattern-claims.toml (the claims of
Bougie, Kreft, Swift and Swinney 2005 for the onset study) holds P1, P2, ... each once and in
order, every field of the right type, a known comparison with a well-formed band, a band
justification and a source for every claim, case files that exist in validation/cases, and,
for a provisional claim, what of the paper it still needs.

It then checks that the checker catches broken copies (a missing field, a duplicated id, an
empty or reversed band, a band of the wrong length, an unknown comparison, no source, a case
without a file, a provisional claim that says nothing is missing), so that a pass means
something.
"""
import math
import os
import tomllib

import pytest

from .. import REPOSITORY, edited_copy

VALIDATION = os.path.join(REPOSITORY, "validation")
CLAIMS_FILE = os.path.join(REPOSITORY, "reference-data", "pattern-claims.toml")

FIELDS = {"id": str, "statement": str, "paper_value": str, "source": str, "cases": list,
          "quantity": str, "comparison": str, "band": list, "band_justification": str,
          "solvers": str, "status": str, "missing": str}
MAY_BE_EMPTY = {"band", "missing"}
BAND_LENGTH = {"range": 2, "outside": 2, "less_than": 1, "greater_than": 1, "true": 0}
SOLVERS = {"md", "continuum", "both", "md_vs_continuum"}
STATUSES = {"measurable", "provisional"}


def check_band(claim, where, errors):
    comparison, band = claim.get("comparison"), claim.get("band")
    if comparison not in BAND_LENGTH:
        errors.append(f"{where}: unknown comparison '{comparison}'")
        return
    if not isinstance(band, list) or len(band) != BAND_LENGTH[comparison]:
        errors.append(f"{where}: comparison '{comparison}' needs a band of "
                      f"{BAND_LENGTH[comparison]} numbers, got {band!r}")
    elif not all(isinstance(b, (int, float)) and math.isfinite(b) for b in band):
        errors.append(f"{where}: band {band!r} is not finite numbers")
    elif len(band) == 2 and not band[0] < band[1]:
        errors.append(f"{where}: band {band!r} is empty or reversed")


def check_fields(claim, where, errors):
    for field, kind in FIELDS.items():
        if field not in claim:
            errors.append(f"{where}: field '{field}' missing")
        elif not isinstance(claim[field], kind):
            errors.append(f"{where}: field '{field}' is not a {kind.__name__}")
        elif field not in MAY_BE_EMPTY and not claim[field]:
            errors.append(f"{where}: field '{field}' is empty")
        elif kind is str and field not in MAY_BE_EMPTY and not claim[field].strip():
            errors.append(f"{where}: field '{field}' is blank")


def validate(claims, cases_dir):
    errors = []
    ids = [c.get("id") for c in claims]
    expected = [f"P{n}" for n in range(1, len(claims) + 1)]
    if ids != expected:
        errors.append(f"ids {ids} are not {expected} (each once, in order)")
    for claim in claims:
        where = claim.get("id", "?")
        check_fields(claim, where, errors)
        check_band(claim, where, errors)
        if claim.get("solvers") not in SOLVERS:
            errors.append(f"{where}: solvers must be one of {sorted(SOLVERS)}")
        if claim.get("status") not in STATUSES:
            errors.append(f"{where}: status must be one of {sorted(STATUSES)}")
        elif claim["status"] == "provisional" and not str(claim.get("missing", "")).strip():
            errors.append(f"{where}: a provisional claim must say what of the paper it needs")
        if "Bougie" not in claim.get("source", "") and "et al." not in claim.get("source", ""):
            errors.append(f"{where}: source names no paper")
        for case in claim.get("cases", []):
            if not os.path.isfile(os.path.join(cases_dir, f"{case}.toml")):
                errors.append(f"{where}: case '{case}' has no file validation/cases/{case}.toml")
    return errors


def load_claims():
    with open(CLAIMS_FILE, "rb") as f:
        return tomllib.load(f)["claim"]


CLAIMS = load_claims()
CASES = os.path.join(VALIDATION, "cases")


def broken_copies(claims):
    """(description, broken claims list) pairs the checker must reject."""
    def edit(change):
        return edited_copy(claims, change)
    return [
        ("missing field", edit(lambda c: c[2].pop("band_justification"))),
        ("duplicated id", edit(lambda c: c[1].update(id="P1"))),
        ("empty band", edit(lambda c: c[1].update(band=[1.1, 1.1]))),
        ("reversed band", edit(lambda c: c[1].update(band=[1.16, 1.04]))),
        ("band of the wrong length", edit(lambda c: c[2].update(band=[1.0, 2.0]))),
        ("non-finite band", edit(lambda c: c[2].update(band=[float("nan")]))),
        ("unknown comparison", edit(lambda c: c[0].update(comparison="about"))),
        ("no source", edit(lambda c: c[3].update(source=" "))),
        ("case without a file", edit(lambda c: c[0].update(cases=["pattern_nowhere"]))),
        ("provisional with nothing missing", edit(lambda c: c[1].update(missing=""))),
        ("unknown solvers", edit(lambda c: c[0].update(solvers="lattice"))),
    ]


def test_pattern_claims_file_is_clean():
    errors = validate(CLAIMS, CASES)
    assert errors == [], f"pattern-claims.toml: {len(CLAIMS)} claims: {errors}"
    assert len(CLAIMS) >= 8


@pytest.mark.parametrize("description, broken", broken_copies(CLAIMS),
                         ids=[d for d, _ in broken_copies(CLAIMS)])
def test_broken_pattern_claims_are_caught(description, broken):
    assert validate(broken, CASES), f"broken copy ({description}) NOT CAUGHT"
