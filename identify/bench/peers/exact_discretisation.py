#!/usr/bin/env python3
"""The peer scoleid is timed against on EI(x): what a careful user writes with numpy and scipy.

The same Euler-Bernoulli finite-element model scoleid fits (cubic Hermite elements, consistent
mass, pinned ends, EI constant on each of N equal sections), discretised exactly for inputs that
are linear between samples (first-order hold): one matrix exponential of the augmented matrix

    [[A, B, 0], [0, 0, I/dt], [0, 0, 0]] * dt,   A = [[0, I], [-M^-1 K, 0]],

per evaluation (scipy.linalg.expm), then x_{k+1} = Phi x_k + Gamma0 u_k + Gamma1 u_{k+1}. The fit is
scipy.optimize.least_squares on the sensors' residuals with its defaults (trust-region reflective,
forward-difference Jacobian: one extra evaluation per parameter), in EI over its starting value,
bounded below by 1e-3 of it.

Usage: exact_discretisation.py PROBLEM.json    (written by scole-sections-bench --part 4)
Prints one JSON line: wall_seconds, evaluations (Jacobian columns included), function_evaluations
(least_squares' own count), estimate, cost, status.
"""
import json
import sys
import time

import numpy as np
from scipy.linalg import expm
from scipy.optimize import least_squares


def hermite(xi, le):
    """Cubic Hermite shape functions at xi in [0, 1] on an element of length le."""
    return np.array([1 - 3 * xi**2 + 2 * xi**3, le * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3,
                     le * (-xi**2 + xi**3)])


class Beam:
    def __init__(self, p):
        self.L = p["length"]
        self.ne = p["elements"]
        self.sections = p["sections"]
        self.rho_a = p["rho_A"]
        le = self.L / self.ne
        self.le = le
        n = 2 * (self.ne + 1)
        ke = np.array([[12, 6 * le, -12, 6 * le], [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                       [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le**2, -6 * le, 4 * le**2]]) / le**3
        me = np.array([[156, 22 * le, 54, -13 * le], [22 * le, 4 * le**2, 13 * le, -3 * le**2],
                       [54, 13 * le, 156, -22 * le], [-13 * le, -3 * le**2, -22 * le, 4 * le**2]]) * le / 420
        # Unit-EI stiffness of each section and the mass, on all dofs, then the supports removed.
        self.k_sections = [np.zeros((n, n)) for _ in range(self.sections)]
        m = np.zeros((n, n))
        for e in range(self.ne):
            idx = np.arange(2 * e, 2 * e + 4)
            sec = min(self.sections - 1, int((e + 0.5) * self.sections / self.ne))
            self.k_sections[sec][np.ix_(idx, idx)] += ke
            m[np.ix_(idx, idx)] += self.rho_a * me
        keep = [i for i in range(n) if i not in (0, n - 2)]  # pinned: w = 0 at both ends
        self.keep = keep
        self.k_sections = [k[np.ix_(keep, keep)] for k in self.k_sections]
        self.m = m[np.ix_(keep, keep)]
        self.minv = np.linalg.inv(self.m)
        self.nd = len(keep)

    def row(self, x):
        """A row on the kept dofs reading w(x)."""
        e = min(self.ne - 1, int(x / self.le))
        full = np.zeros(2 * (self.ne + 1))
        full[2 * e:2 * e + 4] = hermite(x / self.le - e, self.le)
        return full[self.keep]


def simulate(beam, ei, loads_b, c, u, dt):
    nd = beam.nd
    k = sum(ei_k * k_k for ei_k, k_k in zip(ei, beam.k_sections))
    a = np.zeros((2 * nd, 2 * nd))
    a[:nd, nd:] = np.eye(nd)
    a[nd:, :nd] = -beam.minv @ k
    b = np.zeros((2 * nd, loads_b.shape[1]))
    b[nd:, :] = beam.minv @ loads_b
    m = b.shape[1]
    big = np.zeros((2 * nd + 2 * m, 2 * nd + 2 * m))
    big[:2 * nd, :2 * nd] = a * dt
    big[:2 * nd, 2 * nd:2 * nd + m] = b * dt
    big[2 * nd:2 * nd + m, 2 * nd + m:] = np.eye(m)
    e = expm(big)
    phi = e[:2 * nd, :2 * nd]
    g1 = e[:2 * nd, 2 * nd + m:]           # multiplies u_{k+1} - u_k
    g0 = e[:2 * nd, 2 * nd:2 * nd + m] - g1  # multiplies u_k
    x = np.zeros(2 * nd)
    y = np.zeros((u.shape[0], c.shape[0]))
    for i in range(u.shape[0]):
        y[i] = c @ x[:nd]
        if i + 1 < u.shape[0]:
            x = phi @ x + g0 @ u[i] + g1 @ u[i + 1]
    return y


def main():
    with open(sys.argv[1]) as f:
        p = json.load(f)
    t0 = time.perf_counter()
    beam = Beam(p)
    t = np.asarray(p["t"])
    dt = t[1] - t[0]
    data = np.asarray(p["data"]).T           # samples x sensors
    u = np.asarray(p["loads"]).T             # samples x loads
    c = np.array([beam.row(x) for x in p["sensor_locations"]])
    loads_b = np.array([beam.row(x) for x in p["load_locations"]]).T
    scale = np.asarray(p["initial_EI"], dtype=float)
    evaluations = 0

    def residual(z):
        nonlocal evaluations
        evaluations += 1
        return (simulate(beam, z * scale, loads_b, c, u, dt) - data).ravel()

    # EI stays positive (a step to EI <= 0 makes the model unstable and the residuals overflow).
    fit = least_squares(residual, np.ones(len(scale)), bounds=(1e-3, np.inf))
    wall = time.perf_counter() - t0
    print(json.dumps({"wall_seconds": wall, "evaluations": evaluations, "function_evaluations": int(fit.nfev),
                      "estimate": list(fit.x * scale), "cost": float(fit.cost), "status": int(fit.status)}))


if __name__ == "__main__":
    main()
