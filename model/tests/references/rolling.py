#!/usr/bin/env python3
"""High-precision references for model/tests/physics/honest_edges.rs: the rolling contact of MODEL.md §3 at
the edges of its range (small κ = (T_ε − T_σ)/T_σ, slow rolling), computed from the exact
closed forms with mpmath at 80 working digits, independently of the Rust solver.

    pip install mpmath
    python3 model/tests/references/rolling.py          # prints the Rust constants (about 3 min)

Every input is the IEEE double the Rust test builds (printed with repr, which round-trips);
the reference is the exact answer for those doubles: k = E_L/H, κ = (T_ε − T_σ)/T_σ and so
on are formed here in 80 digits, not in double precision. Each value is printed as the
nearest double, with its first 25 digits in a comment.

Method (MODEL.md §3), nothing shared with the Rust code but the formulas:
- exit root: the literal G(s) = 1 − s² + (2κ/β²)[(sβ + 1) − (β + 1)e^{β(s−1)}], solved as
  g(ρ) = G(ρ − 1)/(2 − ρ) = 0 (ρ = 1 + a/b; g increasing and convex) by Newton's method
  under a bisection bracket, to 60 digits; for fast strips (β < 1), where the literal form
  cancels down to O(β³), the working precision grows by 3 digits per decade of 1/β;
- strip load q and moment m: the literal exact closed forms of §3;
- y = r sin θ, written as θ = π/2 − t so that cos θ = sin t keeps its digits at the tips;
  t ∈ [0, π/2] cut into panels graded geometrically towards t = 0 down to 1/100 of
  λ_σ/r (where the strips turn fast: the exit root varies on the scale β = b/λ_σ ≈ 1),
  Gauss–Legendre on each panel; 40 nodes per panel, checked against 56;
- the load equation P(δ) = P by secant steps in ln r, r = √(2Rδ), to 1e-45.
"""

import sys

import mpmath as mp

mp.mp.dps = 80
NODES, CHECK_NODES = 40, 56


def exact(x):
    """The double x as an exact mpf."""
    return mp.mpf(float(x))


class Case:
    def __init__(self, name, radius, load, velocity, retardation, relaxation,
                 modulus=3e9, thickness=100e-9, poisson=0.35):
        self.name = name
        self.inputs = (radius, load, velocity, retardation, relaxation)
        self.R, self.P, self.V = exact(radius), exact(load), exact(velocity)
        self.Te, self.Ts = exact(retardation), exact(relaxation)
        self.E, self.H, self.nu = exact(modulus), exact(thickness), exact(poisson)
        self.k = self.E / self.H
        self.kappa = (self.Te - self.Ts) / self.Ts
        self.ls, self.le = self.V * self.Ts, self.V * self.Te
        self.tau = self.E / (2 * (1 + self.nu)) / 1000
        self.roots = {}


def exit_rho(beta, kappa, guess=None):
    """ρ = 1 + a/b of a strip, from the literal exit equation G(s) = 0 of MODEL.md §3, to 60
    digits. For fast strips (β < 1) the bracket of G cancels down to O(β³): the working
    precision grows to make up for it."""
    extra = max(0, int(-3 * mp.log10(beta))) + 10 if beta < 1 else 0
    with mp.workdps(mp.mp.dps + extra):
        return +_exit_rho(mp.mpf(beta), mp.mpf(kappa), guess)


def _exit_rho(beta, kappa, guess):
    def g(rho):
        s = rho - 1
        e = mp.exp(beta * (s - 1))
        G = 1 - s * s + 2 * kappa / beta**2 * ((s * beta + 1) - (beta + 1) * e)
        dG = -2 * s + 2 * kappa / beta * (1 - (beta + 1) * e)
        return G / (1 - s), (dG * (1 - s) + G) / (1 - s) ** 2

    lo, hi = mp.mpf(0), mp.mpf(2)
    if guess is None:
        guess = min(mp.mpf(2) / 3 * kappa * beta / (1 + kappa), kappa / beta)
    rho = min(max(guess, mp.mpf(10) ** -300), mp.mpf("1.9"))
    for _ in range(400):
        value, slope = g(rho)
        if value > 0:
            hi = rho
        else:
            lo = rho
        step = value / slope
        if abs(step) <= mp.mpf(10) ** -60 * rho:
            return rho - step
        rho = rho - step
        if not lo < rho < hi:
            rho = (lo + hi) / 2
    raise RuntimeError(f"exit root: β = {beta}, κ = {kappa}")


def panels(case, r):
    """Panels in t = π/2 − θ, graded towards t = 0 (the lateral tips)."""
    scale = case.ls / r if case.ls > 0 else mp.mpf(1)
    edges = [mp.pi / 2]
    while edges[-1] > scale / 100:
        edges.append(edges[-1] / 2)
    edges.append(mp.mpf(0))
    return list(zip(edges[1:], edges[:-1]))


def integrals(case, r, nodes):
    """(P, A, ∫(b² − a²)dy over y > 0, 2∫m dy over y > 0) at half-width r."""
    X, W = mp.gauss_quadrature(nodes, "legendre")
    kR = case.k / case.R
    total = [mp.mpf(0)] * 4
    elastic = case.V == 0 or case.kappa == 0
    for p, (t0, t1) in enumerate(panels(case, r)):
        half, mid = (t1 - t0) / 2, (t1 + t0) / 2
        for i, (x, w) in enumerate(zip(X, W)):
            t = mid + half * x
            cos_theta = mp.sin(t)
            b = r * cos_theta
            if elastic:
                rho = mp.mpf(0)
            else:
                key = (nodes, p, i)
                rho = exit_rho(b / case.ls, case.kappa, case.roots.get(key))
                case.roots[key] = rho
            a = (rho - 1) * b
            q = kR * ((b - a) ** 2 * (2 * b + a) / 6 + case.le * (b * b - a * a) / 2)
            m = kR / 2 * ((b * b - a * a) ** 2 / 4
                          + mp.mpf(2) / 3 * case.le * (b**3 - a**3)) - case.ls * q
            jacobian = w * half * r * cos_theta  # dy = r cos θ dθ
            for j, f in enumerate((2 * q, 2 * (b - a), b * b - a * a, 2 * m)):
                total[j] += jacobian * f
    return total


def solve(case):
    """Every reported quantity of the rolling answer, and the quadrature check."""
    delta0 = mp.sqrt(case.P / (mp.pi * case.k * case.R))
    r0 = mp.sqrt(2 * case.R * delta0)
    target = mp.log(case.P)

    def f(u):
        return mp.log(integrals(case, mp.exp(u), NODES)[0]) - target

    u0 = mp.log(r0)
    f0 = f(u0)
    u1 = u0 - f0 / 4
    for _ in range(60):
        f1 = f(u1)
        if f1 == f0:
            break
        u0, f0, u1 = u1, f1, u1 - f1 * (u1 - u0) / (f1 - f0)
        if abs(u1 - u0) < mp.mpf(10) ** -45:
            break
    r = mp.exp(u1)
    load, area, area_moment, moment = integrals(case, r, NODES)
    check = integrals(case, r, CHECK_NODES)
    quadrature = max(abs(c / v - 1) for c, v in zip(check, (load, area, area_moment, moment))
                     if v != 0)
    residual = abs(load / case.P - 1)
    xc = area_moment / area
    xp = moment / load
    a0 = mp.pi * r0 * r0
    return {
        "penetration": r * r / (2 * case.R),
        "contact_area": area,
        "half_width": r,
        "centroid_shift": xc,
        "pressure_centre_shift": xp,
        "rolling_resistance_coefficient": xp / case.R,
        "friction_coefficient": case.tau * area / case.P,
        "static_penetration": delta0,
        "static_contact_area": a0,
        "static_friction_coefficient": case.tau * a0 / case.P,
    }, quadrature, residual


CASES = [
    # name, R, P, V, T_ε, T_σ: small κ at the §5 defaults (T_ε − T_σ = 1e-13, 1e-10, 1e-6 s)
    Case("KAPPA_1E_12", 25e-9, 1e-9, 4e-9, 0.1 + 1e-13, 0.1),
    Case("KAPPA_1E_9", 25e-9, 1e-9, 4e-9, 0.1 + 1e-10, 0.1),
    Case("KAPPA_1E_5", 25e-9, 1e-9, 4e-9, 0.1 + 1e-6, 0.1),
    # slow rolling at the §5 defaults (κ = 4)
    Case("V_1E_13", 25e-9, 1e-9, 1e-13, 0.5, 0.1),
    Case("V_1E_12", 25e-9, 1e-9, 1e-12, 0.5, 0.1),
    Case("V_1E_11", 25e-9, 1e-9, 1e-11, 0.5, 0.1),
    Case("V_1E_10", 25e-9, 1e-9, 1e-10, 0.5, 0.1),
    Case("V_1E_9", 25e-9, 1e-9, 1e-9, 0.5, 0.1),
    # where the old estimate fell furthest short: the tip layer unresolved by the rule and
    # its companion alike
    Case("V_5_6E_13", 25e-9, 1e-9, 5.62e-13, 0.5, 0.1),
    Case("K0_01_V_4_5E_12", 25e-9, 1e-9, 4.47e-12, 0.101, 0.1),
    # both at once, and the §3 table's V = 4 nm/s row as a check of this script
    Case("SLOW_KAPPA_1E_12", 25e-9, 1e-9, 1e-12, 0.1 + 1e-13, 0.1),
    Case("TABLE_ROW", 25e-9, 1e-9, 4e-9, 0.5, 0.1),
    # across ξ and κ, where only rounding and the load residual are left
    Case("K4_V_1E_8", 25e-9, 1e-9, 1e-8, 0.5, 0.1),
    Case("K4_V_4E_8", 25e-9, 1e-9, 4.2e-8, 0.5, 0.1),
    Case("K4_V_1E_6", 25e-9, 1e-9, 1e-6, 0.5, 0.1),
    Case("K4_V_1E_5", 25e-9, 1e-9, 1e-5, 0.5, 0.1),
    Case("K100_V_9E_9", 25e-9, 1e-9, 8.66e-9, 10.1, 0.1),
    Case("K100_V_3E_8", 25e-9, 1e-9, 2.74e-8, 10.1, 0.1),
    Case("K100_V_1E_6", 25e-9, 1e-9, 1e-6, 10.1, 0.1),
    Case("K1E4_V_1E_9", 25e-9, 1e-9, 1.33e-9, 1000.1, 0.1),
    Case("K1E4_V_6E_7", 25e-9, 1e-9, 6.49e-7, 1000.1, 0.1),
    Case("K1E4_V_6E_6", 25e-9, 1e-9, 6.49e-6, 1000.1, 0.1),
    Case("K0_01_V_1E_8", 25e-9, 1e-9, 1e-8, 0.101, 0.1),
    Case("K0_01_V_1E_6", 25e-9, 1e-9, 1e-6, 0.101, 0.1),
]

FIELDS = ["penetration", "contact_area", "half_width", "centroid_shift",
          "pressure_centre_shift", "rolling_resistance_coefficient", "friction_coefficient",
          "static_penetration", "static_contact_area", "static_friction_coefficient"]


def main():
    names = set(sys.argv[1:])
    for case in CASES:
        if names and case.name not in names:
            continue
        values, quadrature, residual = solve(case)
        radius, load, velocity, retardation, relaxation = case.inputs
        print(f"// quadrature check {mp.nstr(quadrature, 3)}, load residual "
              f"{mp.nstr(residual, 3)}", file=sys.stderr)
        print(f"const {case.name}: Reference = Reference {{")
        print(f"    radius: {radius!r},\n    load: {load!r},\n    velocity: {velocity!r},")
        print(f"    retardation_time: {retardation!r},\n    relaxation_time: {relaxation!r},")
        print("    values: [")
        for field in FIELDS:
            # The nearest double (it errs by at most 1.1e-16, far below what the tests
            # resolve), and the reference to 25 digits beside it.
            digits = mp.nstr(values[field], 25, min_fixed=1, max_fixed=0)
            print(f"        {float(values[field])!r}, // {field} = {digits}")
        print("    ],\n};")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
