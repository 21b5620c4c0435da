#!/usr/bin/python3
"""Independent reference values for verification/unit/test_granular_model.cpp.

Every value is computed here with 50-digit arithmetic (mpmath), straight from the formulas of
docs/models.md and the kinetic-theory literature, without looking at the C++ code:
  * state inputs are the exact binary values of the C++ double literals (mpf(float(text)));
  * model constants are the spec's decimal values (nu_max = 0.65 exactly, pi to 50 digits);
  * dG/dnu, dchi/dnu and the dchi/dnu inside the sound speed are obtained by mpmath's
    high-precision numerical differentiation (mp.diff), not by the closed form the C++ uses;
  * Haff's law is obtained by integrating the energy balance (3/2) n dT/dt = -gamma(n, T)
    with mpmath's Taylor-series ODE solver (mp.odefun), not by the closed form;
  * the Enskog collision frequency is the textbook hard-sphere value
    4 n sigma^2 g0 sqrt(pi T / m) (Chapman & Cowling) with the Carnahan-Starling g0;
  * shaker kinematics: z_p = A (1 - cos w t), V_p = dz_p/dt and a_p = d2z_p/dt2 by mp.diff.
The output is a C++ include file, reference_values.inc, next to this script. mpmath is not a
project dependency (apt-get install python3-mpmath to regenerate); the generated file is
committed.

Usage: /usr/bin/python3 reference_values.py [OUTPUT]
"""
import pathlib
import sys

import mpmath as mp

mp.mp.dps = 50

NU_MAX = mp.mpf("0.65")
PI = mp.pi


def exact(text):
    """The exact value of the C++ double literal `text`."""
    return mp.mpf(float(text))


# ---- the model of docs/models.md ----------------------------------------------------------
def g0(nu):
    return 1 / (1 - (nu / NU_MAX) ** (mp.mpf(4) / 3 * NU_MAX))


def G(nu):
    return nu * g0(nu)


def chi(nu, e):
    return 1 + 2 * (1 + e) * G(nu)


def volume_fraction(n):
    return PI / 6 * n


def pressure(n, T, e):
    return n * T * (1 + 2 * (1 + e) * G(volume_fraction(n)))


def loss(n, T, e):
    return 12 / mp.sqrt(PI) * (1 - e**2) * n * T ** mp.mpf(1.5) * G(volume_fraction(n))


def bulk(n, T):
    return 8 / (3 * mp.sqrt(PI)) * n * mp.sqrt(T) * G(volume_fraction(n))


def shear(n, T, full):
    g = G(volume_fraction(n))
    inverse = 5 / (16 * g) if full else 0
    return mp.sqrt(PI) / 6 * n * mp.sqrt(T) * (inverse + 1 + mp.mpf(4) / 5 * (1 + 12 / PI) * g)


def conductivity(n, T, full):
    g = G(volume_fraction(n))
    inverse = 5 / (24 * g) if full else 0
    return (15 * mp.sqrt(PI) / 16 * n * mp.sqrt(T)
            * (inverse + 1 + mp.mpf(6) / 5 * (1 + 32 / (9 * PI)) * g))


def sound_speed(nu, T, e):
    x = chi(nu, e)
    dx = mp.diff(lambda v: chi(v, e), nu)
    return mp.sqrt(T * x * (1 + mp.mpf(2) / 3 * x + nu / x * dx))


def mean_free_path(n):
    return mp.sqrt(PI / 8) / (n * PI)


def g0_cs(nu):
    return (1 - nu / 2) / (1 - nu) ** 3


def z_cs(nu):
    return (1 + nu + nu**2 - nu**3) / (1 - nu) ** 3


def enskog(n, T):
    return 4 * n * g0_cs(volume_fraction(n)) * mp.sqrt(PI * T)


def haff(t, T0, Gvalue, e):
    # (3/2) n dT/dt = -gamma = -(12/sqrt(pi)) (1 - e^2) n T^(3/2) G: n cancels.
    rate = mp.mpf(2) / 3 * 12 / mp.sqrt(PI) * (1 - e**2) * Gvalue
    with mp.workdps(30):
        solution = mp.odefun(lambda _, T: -rate * T ** mp.mpf(1.5), 0, T0)
        return solution(t)


# ---- the states ------------------------------------------------------------------------------
# (nu, e): dilute, intermediate, nu = 0.3, dense near 0.6 and very close to nu_max.
NU_CASES = [("1e-4", "0.9"), ("1e-3", "0.9"), ("0.05", "0.7"), ("0.3", "0.9"), ("0.3", "1.0"),
            ("0.45", "0.0"), ("0.6", "0.9"), ("0.64", "0.5")]
# (n, T, e): n = 6 nu / pi for nu ~ 1e-3, 0.05, 0.3, 0.6.
NT_CASES = [("0.002", "1.0", "0.9"), ("0.095", "0.37", "0.7"), ("0.573", "2.5", "0.9"),
            ("0.573", "0.0", "0.9"), ("1.146", "0.01", "0.9"), ("1.146", "4.0", "1.0"),
            ("1.2", "0.8", "0.0")]
# (nu, T, e) for the speed of sound.
SOUND_CASES = [("1e-3", "1.0", "0.9"), ("0.05", "0.2", "0.7"), ("0.3", "1.0", "0.9"),
               ("0.3", "3.0", "1.0"), ("0.6", "0.5", "0.9"), ("0.64", "0.02", "0.0")]
# (t, T0, G, e) for Haff's law.
HAFF_CASES = [("0.0", "1.0", "0.5", "0.9"), ("2.5", "1.0", "0.5", "0.9"),
              ("10.0", "3.0", "1.7", "0.7"), ("0.3", "0.04", "8.9", "0.0"),
              ("5.0", "2.0", "0.3", "1.0")]
# (Gamma, f, t): the base case and two others; t away from zeros of sin and cos.
SHAKER_CASES = [("3.0", "0.095", "0.7"), ("3.0", "0.095", "3.1"), ("3.0", "0.095", "7.9"),
                ("3.0", "0.095", "41.9"), ("2.2", "0.25", "1.3"), ("7.0", "0.05", "13.0")]
# (kind, e, normal speed) for the restitution model of docs/models.md.
RESTITUTION_CASES = [("constant", "0.9", "0.3"), ("constant", "0.7", "5.0"),
                     ("velocity_dependent", "0.9", "0.0"),
                     ("velocity_dependent", "0.9", "0.01"),
                     ("velocity_dependent", "0.9", "0.5"),
                     ("velocity_dependent", "0.9", "0.999999"),
                     ("velocity_dependent", "0.9", "1.0"),
                     ("velocity_dependent", "0.9", "1.5"),
                     ("velocity_dependent", "0.9", "40.0")]


def restitution(kind, e, speed):
    if kind == "constant":
        return e
    return 1 - mp.mpf("0.1") * speed ** mp.mpf("0.75") if speed < 1 else mp.mpf("0.9")


def literal(x):
    return mp.nstr(x, 25, min_fixed=-mp.inf, max_fixed=mp.inf, strip_zeros=False) \
        if x != 0 else "0.0"


def row(items):
    return "    {" + ", ".join(items) + "},"


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else \
        pathlib.Path(__file__).with_name("reference_values.inc")
    lines = ["// Generated by verification/unit/reference_values.py (mpmath, 50 digits); "
             "do not edit.",
             "// Each row: inputs (the C++ literals), then the expected values.", ""]

    lines.append("// nu, e | g0, G, dG/dnu (mp.diff), chi, dchi/dnu (mp.diff), g0_CS, Z_CS")
    lines.append("inline constexpr NuReference nu_references[] = {")
    for nu_t, e_t in NU_CASES:
        nu, e = exact(nu_t), exact(e_t)
        values = [g0(nu), G(nu), mp.diff(G, nu), chi(nu, e), mp.diff(lambda v: chi(v, e), nu),
                  g0_cs(nu), z_cs(nu)]
        lines.append(row([nu_t, e_t] + [literal(v) for v in values]))
    lines += ["};", ""]

    lines.append("// n, T, e | p, gamma, lambda, mu_paper, mu_full, kappa_paper, kappa_full, "
                 "Enskog frequency, xi")
    lines.append("inline constexpr StateReference state_references[] = {")
    for n_t, T_t, e_t in NT_CASES:
        n, T, e = exact(n_t), exact(T_t), exact(e_t)
        values = [pressure(n, T, e), loss(n, T, e), bulk(n, T), shear(n, T, False),
                  shear(n, T, True), conductivity(n, T, False), conductivity(n, T, True),
                  enskog(n, T), mean_free_path(n)]
        lines.append(row([n_t, T_t, e_t] + [literal(v) for v in values]))
    lines += ["};", ""]

    lines.append("// nu, T, e | c")
    lines.append("inline constexpr SoundReference sound_references[] = {")
    for nu_t, T_t, e_t in SOUND_CASES:
        lines.append(row([nu_t, T_t, e_t, literal(sound_speed(exact(nu_t), exact(T_t),
                                                              exact(e_t)))]))
    lines += ["};", ""]

    lines.append("// t, T0, G, e | T(t) by integrating (3/2) n dT/dt = -gamma")
    lines.append("inline constexpr HaffReference haff_references[] = {")
    for t_t, T0_t, G_t, e_t in HAFF_CASES:
        value = haff(exact(t_t), exact(T0_t), exact(G_t), exact(e_t))
        lines.append(row([t_t, T0_t, G_t, e_t, literal(value)]))
    lines += ["};", ""]

    lines.append("// Gamma, f, t | A, omega, z_p, V_p, a_p, phase f t mod 1")
    lines.append("inline constexpr ShakerReference shaker_references[] = {")
    for Gamma_t, f_t, t_t in SHAKER_CASES:
        Gamma, f, t = exact(Gamma_t), exact(f_t), exact(t_t)
        omega = 2 * PI * f
        A = Gamma / omega**2
        position = lambda s: A * (1 - mp.cos(omega * s))  # noqa: E731
        values = [A, omega, position(t), mp.diff(position, t), mp.diff(position, t, 2),
                  mp.frac(f * t)]
        for v in values[2:]:
            assert abs(v) > mp.mpf("1e-3") * A, "choose t away from zeros"
        lines.append(row([Gamma_t, f_t, t_t] + [literal(v) for v in values]))
    lines += ["};", ""]

    lines.append("// constant?, e, |v_n| | e(|v_n|)")
    lines.append("inline constexpr RestitutionReference restitution_references[] = {")
    for kind, e_t, v_t in RESTITUTION_CASES:
        value = restitution(kind, exact(e_t), exact(v_t))
        lines.append(row(["true" if kind == "constant" else "false", e_t, v_t, literal(value)]))
    lines += ["};", ""]

    out.write_text("\n".join(lines))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
