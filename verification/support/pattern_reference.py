"""The pattern quantities of docs/analysis.md ("Patterns") computed independently with numpy's
FFT, for the tests of `shaker analyze --patterns` on MD particle files
(verification/md/test_pattern_cli.py) and continuum fields files
(verification/continuum/test_pattern_fields_cli.py)."""
import numpy as np


def wavenumbers(shape, edges):
    """(KX, KY) of numpy's fft2 modes of a field [y, x], the Nyquist mode of an even n counted
    positive as the analysis counts it."""
    ny, nx = shape
    kx = 2 * np.pi * np.fft.fftfreq(nx, d=edges[0] / nx)
    ky = 2 * np.pi * np.fft.fftfreq(ny, d=edges[1] / ny)
    kx[nx // 2] = abs(kx[nx // 2]) if nx % 2 == 0 else kx[nx // 2]
    ky[ny // 2] = abs(ky[ny // 2]) if ny % 2 == 0 else ky[ny // 2]
    return np.meshgrid(kx, ky)


def measure(field, edges):
    """k*, wavelength, A2, A4, A6 and order parameter by the definitions of docs/analysis.md."""
    power = np.abs(np.fft.fft2(field - field.mean()))**2 / field.size**2
    KX, KY = wavenumbers(field.shape, edges)
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


def half_wavelength_correlation(before, now, edges):
    """The correlation of `now` with `before` shifted by half a wavelength along the wavevector
    of `now`'s strongest mode (kx > 0, or kx = 0 and ky > 0, of the pair)."""
    fa, fb = np.fft.fft2(before - before.mean()), np.fft.fft2(now - now.mean())
    KX, KY = wavenumbers(now.shape, edges)
    strongest = np.unravel_index(np.argmax(np.abs(fb)), fb.shape)
    k0 = np.array([KX[strongest], KY[strongest]])
    if k0[0] < 0 or (k0[0] == 0 and k0[1] < 0):
        k0 = -k0
    d = np.pi * k0 / (k0 @ k0)
    shifted = fa * np.exp(-1j * (KX * d[0] + KY * d[1]))
    return np.real(np.sum(shifted * np.conj(fb))) / np.sqrt(np.sum(np.abs(fa)**2)
                                                            * np.sum(np.abs(fb)**2))
