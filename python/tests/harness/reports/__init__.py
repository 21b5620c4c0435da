"""pytest tests of the reports package (run by ctest as reports.*)."""
