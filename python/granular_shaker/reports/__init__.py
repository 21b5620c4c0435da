"""The report generators of granular-shaker (make_*_report, one command each: shaker-*-report)
and what they share (report_common, figure_rules). They write into the repository's reports/
by default (granular_shaker.repository)."""
