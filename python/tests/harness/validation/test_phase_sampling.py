"""The agreement rule of the phase-sampling comparison, and its table in the validation
report, on values of known outcome."""
import math

from granular_shaker.reports import make_validation_report as report
from granular_shaker.validation import phase_sampling


def quantities(value, error):
    return {name: (value, error) for name in phase_sampling.SHOCK_QUANTITIES}


def test_rule_on_known_differences():
    coarse = quantities(1.0, 0.1)
    fine = dict(quantities(1.2, 0.1), shock_speed=(1.3, 0.1), lifetime=(None, None))
    fine["exit_phase"] = (1.0 + 2.0 * math.hypot(0.1, 0.1) * 0.999, 0.1)
    rows = {r["quantity"]: r for r in phase_sampling.compare(coarse, fine)}
    assert abs(rows["formation_phase"]["ratio"] - 0.2 / math.hypot(0.1, 0.1)) < 1e-12
    assert rows["formation_phase"]["agrees"] is True       # 1.41 combined errors
    assert rows["exit_phase"]["agrees"] is True            # just inside 2
    assert rows["shock_speed"]["agrees"] is False          # 2.12 combined errors
    assert rows["lifetime"]["agrees"] is False             # measured at one sampling only
    missing = phase_sampling.compare({}, {})
    assert all(r["agrees"] is None for r in missing)       # measured at neither


class Results:
    def __init__(self, sampling):
        self.data = {"sampling": sampling}


def test_report_lists_every_disagreement():
    rows = phase_sampling.compare(quantities(1.0, 0.1), dict(quantities(1.0, 0.1),
                                                             shock_speed=(2.0, 0.1)))
    entry = dict(case="base", phases=[50, 100], status="ok", rows=rows,
                 agreement=phase_sampling.AGREEMENT)
    text = "\n".join(report.sampling_section(Results([entry, dict(entry, case="depth_h4p5")])))
    assert text.count("| **no** |") == 2
    assert text.count("| yes |") == 2 * (len(phase_sampling.SHOCK_QUANTITIES) - 1)
    assert "2 quantities disagree: base shock_speed, depth_h4p5 shock_speed." in text
    assert "| base | shock_speed | sqrt(g sigma) | 50 / 100 |" in text
