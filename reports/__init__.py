"""The report generators (make_*_report) and what they share (report_common)."""
