"""Engineering demand parameters: floor accelerations, storey drifts and shears, base shear.

What engineers judge damage by (docs/model.md, "Demand parameters"), per
floor i of building b, with u_0 = 0 (the base):

* total acceleration a_i = ü_i + s̈ + a_g, m/s²: it jumps where a force
  jumps (a Kelvin–Voigt element's force jumps by c δ̇₀ at impact onset);
* storey drift d_i = u_i − u_{i−1}, m (its ratio to the storey height h_i
  when the building gives ``storey_height``);
* storey shear V_i = k_i d_i + c_i ḋ_i, N; the base shear is V_1, the force
  the first storey passes to the base.

Each is an affine read-out of a mode's state (and, for the acceleration,
of a_g): :func:`demand_rows`. A run asked for demands monitors ± each of
them, so that the peak of its absolute value over the run is located on the
solution, not on the output grid.
"""

from __future__ import annotations

import numpy as np

DEMANDS = ("total_acceleration", "storey_drift", "storey_shear")
"""The demand parameters per floor, in the order of :func:`demand_rows`."""


def demand_rows(floor_dofs: list[np.ndarray], base_dofs: list[int | None], storey_stiffness: list[np.ndarray], storey_damping: list[np.ndarray],
                rate: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every floor's demands as an affine map of x = [q, v] and a_g: (matrix, a_g coefficients, constants).

    Rows: for each parameter of :data:`DEMANDS`, every floor of every
    building, building by building, floor 1 upwards (total floors F: 3F rows).

    Parameters
    ----------
    floor_dofs, base_dofs : list
        Each building's floor DOFs and base DOF (None for a fixed base).
    storey_stiffness, storey_damping : list of np.ndarray
        Each building's storey k_i (N/m) and c_i (N·s/m).
    rate : (A, B, c)
        The mode's ẋ = A ξ + B a_g + c (A over ξ = [x, f]: the rows are over ξ too).
    """
    A, B, c = rate
    n = A.shape[0] // 2
    floors = sum(len(dofs) for dofs in floor_dofs)
    matrix, ground, constant = np.zeros((3 * floors, A.shape[1])), np.zeros(3 * floors), np.zeros(3 * floors)
    row = 0
    for dofs, base, k, damping in zip(floor_dofs, base_dofs, storey_stiffness, storey_damping):
        for i, dof in enumerate(dofs):
            below = dofs[i - 1] if i > 0 else None
            accelerated = [n + dof] + ([n + base] if base is not None else [])
            matrix[row] = A[accelerated].sum(axis=0)
            ground[row] = B[accelerated].sum() + 1.0
            constant[row] = c[accelerated].sum()
            drift = row + floors
            matrix[drift, dof] = 1.0
            if below is not None:
                matrix[drift, below] = -1.0
            matrix[drift + floors, :n] = k[i] * matrix[drift, :n]
            matrix[drift + floors, n : 2 * n] = damping[i] * matrix[drift, :n]  # columns beyond 2N: read-outs (none in a shear)
            row += 1
    return matrix, ground, constant
