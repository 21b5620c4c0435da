"""The bias and the coverage of an estimator's error bars over independent realisations of
known truth: the check every fit of granular_shaker.patterns is trusted by."""
import numpy as np


def coverage(estimates, errors, truth, label="measured"):
    """(deviation from the truth, errors, fraction within 1 error, fraction within 2 errors),
    printed with the mean and median deviation, so that the test log carries the numbers."""
    deviation = np.asarray(estimates, float) - truth
    errors = np.asarray(errors, float)
    one = np.mean(np.abs(deviation) <= errors)
    two = np.mean(np.abs(deviation) <= 2 * errors)
    print(f"{label}: bias {deviation.mean():.2e}, median deviation {np.median(deviation):.2e}, "
          f"spread {deviation.std():.2e}, mean error {errors.mean():.2e}, coverage {one:.3f} "
          f"(1 error), {two:.3f} (2 errors)")
    return deviation, errors, one, two
