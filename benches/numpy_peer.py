"""The NumPy peer of issue 12: the rolling contact of docs/model.md §3 as a researcher would
script it, vectorised over the strips (64 Gauss-Legendre nodes in θ, Newton on every exit
root at once, a secant on the penetration). Prints its answer for the default job next to
the service's, and its time per solve on one thread.

    python3 -m venv /tmp/np && /tmp/np/bin/pip install numpy
    /tmp/np/bin/python benches/numpy_peer.py [target/release/thirdbody]

Not part of CI: a yardstick for BENCHMARKS.md ("≥ 1,000× the NumPy peer per solve").
"""

import json
import subprocess
import sys
import time

import numpy as np

R, P, V = 25e-9, 1e-9, 4e-9
E, H, T_EPS, T_SIG = 3e9, 100e-9, 0.5, 0.1
K = E / H
KAPPA = T_EPS / T_SIG - 1.0
X, W = np.polynomial.legendre.leggauss(64)
THETA = np.pi / 4 * (X + 1.0)
SIN, COS, WEIGHT = np.sin(THETA), np.cos(THETA), np.pi / 4 * W * np.cos(THETA)


def exit_roots(beta):
    """ρ = 1 + a/b of every strip: Newton on g(ρ) = ρ + 2κ[E1(z) + σE2(z)], z = βσ."""
    rho = np.minimum(2 / 3 * KAPPA * beta / (1 + KAPPA), KAPPA / beta).clip(1e-300, 1.9)
    for _ in range(50):
        sigma = rho - 2.0
        z = beta * sigma
        em1 = np.expm1(z)
        e1, e2 = em1 / z, (em1 - z) / (z * z)
        prime = ((em1 + 1.0) * (z - 1.0) + 1.0) / (z * z)
        step = (rho + 2 * KAPPA * (e1 + sigma * e2)) / (1 + 2 * KAPPA * (beta + 1) * prime)
        rho = np.clip(rho - step, 0.0, 2.0)
        if np.all(np.abs(step) <= 1e-9 * rho):
            break
    return rho


def load(delta):
    """P(δ) = 2∫q dy, q = (k/R)[b³(2−ρ)²(1+ρ)/6 + V T_ε b² ρ(2−ρ)/2]."""
    r = np.sqrt(2 * R * delta)
    b = r * COS
    rho = exit_roots(b / (V * T_SIG))
    q = b**3 * (2 - rho) ** 2 * (1 + rho) / 6 + V * T_EPS * b**2 * rho * (2 - rho) / 2
    return 2 * r * np.sum(WEIGHT * q) * K / R


def penetration():
    """δ with P(δ) = P: secant on ln P(ln δ) from the static δ₀."""
    u0 = np.log(np.sqrt(P / (np.pi * K * R)))
    u1 = u0 - 0.01
    f0, f1 = np.log(load(np.exp(u0)) / P), np.log(load(np.exp(u1)) / P)
    for _ in range(50):
        if abs(f1) <= 1e-14 or f1 == f0:
            break
        u0, u1 = u1, u1 - f1 * (u1 - u0) / (f1 - f0)
        f0, f1 = f1, np.log(load(np.exp(u1)) / P)
    return np.exp(u1)


def main():
    delta = penetration()
    runs, start = 0, time.perf_counter()
    while time.perf_counter() - start < 3.0:
        penetration()
        runs += 1
    per_solve = (time.perf_counter() - start) / runs
    print(f"numpy {np.__version__} peer: δ = {delta:.15e} m, {per_solve * 1e6:.0f} µs per solve")
    binary = sys.argv[1] if len(sys.argv) > 1 else "target/release/thirdbody"
    answer = json.loads(subprocess.run([binary, "solve", "-"], input=b'{"kind": "rolling"}',
                                       capture_output=True, check=True).stdout)
    ours = answer["penetration"]
    print(f"thirdbody:  δ = {ours:.15e} m (relative difference {abs(delta / ours - 1):.1e})")


if __name__ == "__main__":
    main()
