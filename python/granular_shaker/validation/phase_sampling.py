"""Whether the shock quantities depend on how finely a run is stored.

The same MD run (same seed, so the same trajectory: the stored phases only add snapshots)
stored at two phase samplings gives per-run shock quantities that must agree within
AGREEMENT combined standard errors of the two analyses (docs/analysis.md). The validation
study runs its cases again at a finer sampling (studies.toml [sampling]) and its report
tables the comparison; verification/sampling/check_phases_per_cycle.py does it for one case.
"""
import math

SHOCK_QUANTITIES = ["formation_phase", "exit_phase", "lifetime", "shock_speed",
                    "shock_width_mean", "width_over_mfp_mean", "max_mach_peak"]
AGREEMENT = 2.0


def _number(x):
    return math.nan if x is None else float(x)


def compare(coarse, fine):
    """Rows per shock quantity: the two (value, error) pairs, |difference| / combined error
    and whether that is within AGREEMENT. `coarse` and `fine` map a quantity to
    (value, error); a quantity neither run measures has agrees = None."""
    rows = []
    for name in SHOCK_QUANTITIES:
        (va, ea), (vb, eb) = ([_number(x) for x in run.get(name, (None, None))]
                              for run in (coarse, fine))
        combined = math.hypot(ea, eb)
        ratio = abs(va - vb) / combined if combined > 0 else math.nan
        measured = not (math.isnan(va) and math.isnan(vb))
        rows.append(dict(quantity=name, coarse=(va, ea), fine=(vb, eb), ratio=ratio,
                         agrees=(ratio <= AGREEMENT) if measured else None))
    return rows
