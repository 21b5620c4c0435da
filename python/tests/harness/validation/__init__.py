"""pytest tests of the validation package (run by ctest as validation.*)."""
