"""The validation study of issue 6: run_validation (runner) and quantities (claims)."""
