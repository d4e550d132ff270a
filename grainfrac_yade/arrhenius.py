"""beta1 and beta2 from the physical constants of paper Eq. 6 (temperature form).

Paper Eq. 6 -> Eq. 7 sets

    beta1 = lambda_r v0 exp(-(E + V_m gamma / rho) / (R T))     [Pa/s]
    beta2 = V / (R T)                                          [1/Pa]

with E + V_m gamma/rho the effective (stress-free) activation energy [J/mol],
V the activation volume [m^3/mol], R the gas constant and T the absolute
temperature.  The paper gives beta1 and beta2 at 25 C only (section 4.1) and no
activation energy, so the temperature form needs the user's E.
"""
from __future__ import annotations

import math

#: Molar gas constant [J/(mol K)] (CODATA 2018, exact).
GAS_CONSTANT = 8.314462618


def betas_from_physical(rate_prefactor: float, activation_energy: float, activation_volume: float,
                        temperature: float) -> tuple:
    """(beta1 [Pa/s], beta2 [1/Pa]) of paper Eq. 6 at ``temperature`` [K]."""
    rt = GAS_CONSTANT * temperature
    return rate_prefactor * math.exp(-activation_energy / rt), activation_volume / rt


def physical_from_betas(beta1: float, beta2: float, activation_energy: float, temperature: float) -> tuple:
    """(rate prefactor lambda_r v0 [Pa/s], activation volume V [m^3/mol]) that reproduce ``beta1``
    and ``beta2`` at ``temperature`` [K] for a given effective activation energy [J/mol] (Eq. 6 inverted)."""
    rt = GAS_CONSTANT * temperature
    return beta1 * math.exp(activation_energy / rt), beta2 * rt
