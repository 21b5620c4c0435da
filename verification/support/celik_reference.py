#!/usr/bin/python3
"""Independent reference numbers for test_convergence.cpp (GCI worked example).

Celik, Ghia, Roache, Freitas, Coleman and Raad, "Procedure for estimation and reporting of
uncertainty due to discretization in CFD applications", J. Fluids Eng. 130 (2008) 078001,
Table 1: three 2D grids, N = 18000, 8000, 4500 cells; phi = 6.063, 5.972, 5.863 (monotonic);
and N = 18000, 4500, 980 with phi = 6.0042, 5.9624, 6.0909 (oscillatory). The representative
spacing of a 2D grid is h = (1/N)^(1/2) (any common area cancels in the ratios).

This script solves the apparent-order equation by bisection on
F(p) = p ln r21 - |ln|eps32/eps21| + ln((r21^p - s)/(r32^p - s))|
(the C++ code uses fixed-point iteration, so the two are independent) in Python floats, and
prints the quantities the C++ test asserts. Run: /usr/bin/python3 celik_reference.py
The paper's Table 1 (first column) quotes, rounded: p = 1.53, phi_ext = 6.1685,
e_a21 = 1.5%, e_ext21 = 1.7%.
"""
import math


def apparent_order(r21, r32, eps21, eps32):
    s = math.copysign(1.0, eps32 / eps21)

    def F(p):
        q = math.log((r21 ** p - s) / (r32 ** p - s))
        return p * math.log(r21) - abs(math.log(abs(eps32 / eps21)) + q)

    lo, hi = 1e-6, 20.0
    assert F(lo) * F(hi) < 0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if F(lo) * F(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def study(cells, phi):
    h = [n ** -0.5 for n in cells]
    r21, r32 = h[1] / h[0], h[2] / h[1]
    eps21, eps32 = phi[1] - phi[0], phi[2] - phi[1]
    p = apparent_order(r21, r32, eps21, eps32)
    rp21, rp32 = r21 ** p, r32 ** p
    ext = (rp21 * phi[0] - phi[1]) / (rp21 - 1)
    ea21 = abs((phi[0] - phi[1]) / phi[0])
    ea32 = abs((phi[1] - phi[2]) / phi[1])
    eext = abs((ext - phi[0]) / ext)
    gci21 = 1.25 * ea21 / (rp21 - 1)
    gci32 = 1.25 * ea32 / (rp32 - 1)
    return dict(h=h, r21=r21, r32=r32, p=p, ext=ext, ea21=ea21, eext21=eext, gci21=gci21,
                gci32=gci32, ratio=gci32 / (rp21 * gci21))


if __name__ == "__main__":
    for name, cells, phi in [("monotonic", (18000, 8000, 4500), (6.063, 5.972, 5.863)),
                             ("oscillatory", (18000, 4500, 980), (6.0042, 5.9624, 6.0909))]:
        print(name)
        for key, value in study(cells, phi).items():
            print(f"  {key} = {value!r}")
