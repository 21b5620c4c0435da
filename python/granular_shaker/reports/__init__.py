"""The report generators of granular-shaker (make_*_report, one command each: shaker-*-report)
and what they share (report_common, figure_rules). They write into the repository's reports/
by default (granular_shaker.repository). The harness imports its modules by their absolute
names, so that a generator also runs by its path when the package is importable
(verification/support's C++ test runs make_convergence_report.py so)."""
