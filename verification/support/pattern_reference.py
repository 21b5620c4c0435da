"""The pattern quantities of docs/analysis.md ("Patterns") computed independently with numpy's
FFT, for the tests of `shaker analyze --patterns` on MD particle files
(verification/md/test_pattern_cli.py) and continuum fields files
(verification/continuum/test_pattern_fields_cli.py)."""
import numpy as np


def measure(field, edges):
    """k*, wavelength, A2, A4, A6 and order parameter by the definitions of docs/analysis.md."""
    ny, nx = field.shape
    power = np.abs(np.fft.fft2(field - field.mean()))**2 / field.size**2
    kx = 2 * np.pi * np.fft.fftfreq(nx, d=edges[0] / nx)
    ky = 2 * np.pi * np.fft.fftfreq(ny, d=edges[1] / ny)
    # numpy puts the Nyquist mode of an even n at negative k; the analysis counts it positive.
    kx[nx // 2] = abs(kx[nx // 2]) if nx % 2 == 0 else kx[nx // 2]
    ky[ny // 2] = abs(ky[ny // 2]) if ny % 2 == 0 else ky[ny // 2]
    KX, KY = np.meshgrid(kx, ky)
    k = np.hypot(KX, KY)
    dk = 2 * np.pi / max(edges[0], edges[1])
    shell = np.floor(k / dk + 0.5).astype(int)
    shell_power = np.bincount(shell[k > 0], weights=power[k > 0])
    peak = int(np.argmax(shell_power))
    near = (k > 0) & (np.abs(shell - peak) <= 1)
    k_star = np.sum(power[near] * k[near]) / np.sum(power[near])
    ring = (k > 0) & (np.abs(k - k_star) <= 1.5 * dk)
    theta = np.arctan2(KY[ring], KX[ring])
    moments = [abs(np.sum(power[ring] * np.exp(1j * m * theta))) / np.sum(power[ring])
               for m in (2, 4, 6)]
    return [k_star, 2 * np.pi / k_star, *moments, np.sqrt(power.sum())]


def correlation(a, b):
    da, db = a - a.mean(), b - b.mean()
    return np.sum(da * db) / np.sqrt(np.sum(da * da) * np.sum(db * db))
