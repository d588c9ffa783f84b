"""Stationary response variance of linear structures under Kanai–Tajimi / Clough–Penzien input.

For a linear structure with transfer function H(ω) from ground acceleration to
a displacement, the stationary response variance is ∫ |H(ω)|² S(ω) dω. The
ensemble here is propagated with the exact first-order-hold discretisation of
the structure (the same interpolation the solvers use), written in this file;
a second test checks that ``stochpound.simulate`` reproduces that propagation
sample by sample, so the variance check carries over to the solver.

Discretisation bias at dt = 0.005 s: the first-order hold attenuates the input
near the first mode by sinc⁴(ω dt/2) (−0.2 % at 20.7 rad/s), and the aliased
Kanai–Tajimi tail adds about +0.1 %: far inside the sampling error (about 1 %).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate
from scipy.linalg import expm, solve_continuous_lyapunov

from stochpound import motions

FIRM = motions.soil_preset("firm")
S0 = 0.05
DT = 0.005

# name: (masses kg, storey stiffnesses N/m, storey dashpots N s/m)
STRUCTURES = {
    "sdof": ([1000.0], [1.0e5], [1000.0]),  # ω = 10 rad/s, ζ = 5 %
    "reference_building": ([26268.0, 17512.0], [24516800.0, 17512000.0], [23634.2, 16881.57]),  # the reference study's Building 1, fixed base
}


def _matrices(masses, stiffnesses, dashpots):
    n = len(masses)
    M = np.diag(masses)
    K = np.zeros((n, n))
    C = np.zeros((n, n))
    for i, (k, c) in enumerate(zip(stiffnesses, dashpots)):
        K[i, i] += k
        C[i, i] += c
        if i > 0:
            K[i - 1, i - 1] += k
            K[i - 1, i] -= k
            K[i, i - 1] -= k
            C[i - 1, i - 1] += c
            C[i - 1, i] -= c
            C[i, i - 1] -= c
    return M, K, C


def _state_space(M, K, C):
    """ẋ = A x + B a_g with x = [u, u̇] (u relative to the ground), M ü + C u̇ + K u = −M 1 a_g."""
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    B = np.concatenate([np.zeros(n), -np.ones(n)])[:, None]
    return A, B


def _foh_propagator(A, B, dt):
    """x_{k+1} = Φ x_k + Γ0 a_k + Γ1 (a_{k+1} − a_k)/dt, exact for piecewise-linear a."""
    n = A.shape[0]
    big = np.zeros((n + 2, n + 2))
    big[:n, :n] = A
    big[:n, n] = B[:, 0]
    big[n, n + 1] = 1.0
    E = expm(big * dt)
    return E[:n, :n], E[:n, n], E[:n, n + 1]


def _propagate(A, B, ground, dt, output):
    """Response ``output`` (state index) to each row of ``ground`` (m/s²), starting at rest."""
    Phi, G0, G1 = _foh_propagator(A, B, dt)
    x = np.zeros((ground.shape[0], A.shape[0]))
    y = np.empty_like(ground)
    y[:, 0] = 0.0
    for k in range(ground.shape[1] - 1):
        a, slope = ground[:, k], (ground[:, k + 1] - ground[:, k]) / dt
        x = x @ Phi.T + a[:, None] * G0 + slope[:, None] * G1
        y[:, k + 1] = x[:, output]
    return y


def _model(kind):
    if kind == "kanai_tajimi":
        return motions.kanai_tajimi_model(**FIRM.kanai_tajimi(), S0=S0)
    return motions.clough_penzien_model(**FIRM.clough_penzien(), S0=S0)


def _target_variance(kind, M, K, C, output_floor):
    """∫ |H(ω)|² S(ω) dω by quadrature of the formulas (split at the resonances)."""
    psd = (lambda w: motions.kanai_tajimi_psd(w, **FIRM.kanai_tajimi(), S0=S0)) if kind == "kanai_tajimi" else (
        lambda w: motions.clough_penzien_psd(w, **FIRM.clough_penzien(), S0=S0)
    )
    ones = np.ones(M.shape[0])

    def integrand(w):
        h = np.linalg.solve(K - w * w * M + 1j * w * C, -M @ ones)[output_floor]
        return abs(h) ** 2 * psd(w)

    modal = np.sqrt(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    points = sorted({*modal, FIRM.omega_g, FIRM.omega_f, *(0.98 * modal), *(1.02 * modal)})
    edges = [0.0, *points, 4 * max(points), np.inf]
    return 2.0 * sum(integrate.quad(integrand, a, b, limit=500, epsrel=1e-10, epsabs=0)[0] for a, b in zip(edges[:-1], edges[1:]))


def _lyapunov_variance(kind, A, B, output):
    """The same variance from the joint (filter + structure) state space: an independent route."""
    Af, Bf, Cf = _model(kind).state_space()
    nf, ns = Af.shape[0], A.shape[0]
    joint = np.block([[Af, np.zeros((nf, ns))], [B @ Cf, A]])
    noise = np.concatenate([Bf[:, 0], np.zeros(ns)])[:, None]
    P = solve_continuous_lyapunov(joint, -2 * np.pi * S0 * noise @ noise.T)
    return P[nf + output, nf + output]


@pytest.mark.parametrize("kind", ["kanai_tajimi", "clough_penzien"])
@pytest.mark.parametrize("structure", list(STRUCTURES))
def test_stationary_response_variance(structure, kind):
    M, K, C = _matrices(*STRUCTURES[structure])
    A, B = _state_space(M, K, C)
    top = M.shape[0] - 1
    target = _target_variance(kind, M, K, C, top)
    assert _lyapunov_variance(kind, A, B, top) == pytest.approx(target, rel=1e-7)

    slowest = min(-np.linalg.eigvals(A).real)  # decay rate of the structure's transient, 1/s
    burn_in = 8.0 / slowest  # transient variance below e^-16
    window = 100.0
    n = 400
    generator = motions.kanai_tajimi if kind == "kanai_tajimi" else motions.clough_penzien
    params = FIRM.kanai_tajimi() if kind == "kanai_tajimi" else FIRM.clough_penzien()
    ground = generator(n, burn_in + window, DT, **params, S0=S0, seed=17).values
    response = _propagate(A, B, ground, DT, top)
    kept = response[:, int(round(burn_in / DT)) :]
    per_realization = np.mean(kept**2, axis=1)
    estimate = per_realization.mean()
    error = per_realization.std(ddof=1) / math.sqrt(n)
    assert abs(estimate - target) < 4.0 * error, (estimate, target, error)
    assert error / target < 0.02  # sharp enough to see a wrong convention or a wrong filter


@pytest.mark.parametrize("kind", ["kanai_tajimi", "clough_penzien"])
@pytest.mark.parametrize("structure", list(STRUCTURES))
def test_solver_reproduces_exact_propagation(structure, kind):
    """stochpound.simulate on a scene with a synthetic [motion] equals the exact propagation above."""
    stochpound = pytest.importorskip("stochpound")
    masses, stiffnesses, dashpots = STRUCTURES[structure]
    params = FIRM.kanai_tajimi() if kind == "kanai_tajimi" else FIRM.clough_penzien()
    motion = {"type": kind, **params, "S0": S0, "seed": 17, "realization": 3, "duration": 4.0, "dt": 0.01}
    scene = stochpound.scene_from_dict(
        {"building": [{"name": "B", "mass": masses, "stiffness": stiffnesses, "damping": dashpots}], "motion": motion}
    )
    run = stochpound.simulate(scene)
    generator = motions.kanai_tajimi if kind == "kanai_tajimi" else motions.clough_penzien
    ground = generator(1, 4.0, 0.01, **params, S0=S0, seed=17, start=3).values
    np.testing.assert_allclose(run["ground_acceleration"].values, ground[0], rtol=0, atol=1e-12)
    M, K, C = _matrices(masses, stiffnesses, dashpots)
    A, B = _state_space(M, K, C)
    top = M.shape[0] - 1
    expected = _propagate(A, B, ground, 0.01, top)[0]
    simulated = run["relative_displacement"].isel(building=0, floor=top).values
    np.testing.assert_allclose(simulated, expected, rtol=0, atol=1e-8 * np.max(np.abs(expected)))
