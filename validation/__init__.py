"""The validation study: run_validation (runner) and quantities (claims)."""
