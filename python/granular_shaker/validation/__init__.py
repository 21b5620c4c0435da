"""The validation study of granular-shaker against the paper, and its continuum sensitivity
study: plan (case files and runs), run (the solvers), views (`shaker analyze` and `shaker
compare` of finished runs), quantities and claims (reference-data/claims.toml against the
views), diagnoses (validation/diagnoses.toml), summary (results.json), cli (shaker-validation),
sensitivity (shaker-sensitivity) and phase_sampling. Their data stays in the repository
(granular_shaker.repository)."""
