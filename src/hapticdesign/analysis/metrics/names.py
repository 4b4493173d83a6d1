"""One vocabulary for the performance metrics of seed 001 (§4, §6, Table 7.3): key, meaning, equation, unit.

Every dictionary of metric values (the ``metrics`` command, the R-CUBE metrics and maps, the
post-evaluation of Table 7.3) uses these keys. Inertia, stiffness and frequency indices keep the
seed's symbols (``I_f``, ``S_f``, ``omega_n``, ...); kinematic ones their names. Units are those of
the R-CUBE (revolute joints: ``J_m`` maps rad/s to m/s, ``M_C`` in kg, ``K_C`` with N/m, N and
N m/rad blocks, eq. 6.54); a device with prismatic joints has m in place of rad.
"""

from __future__ import annotations

from typing import NamedTuple

MANIPULABILITY = "manipulability"
CONDITION_NUMBER = "condition_number"
POSITIONING_RESOLUTION = "positioning_resolution"
INERTIA_VOLUME = "I_m"
INERTIA_FROBENIUS = "I_f"
INERTIA_UNIFORMITY = "I_e"
DYNAMIC_MANIPULABILITY = "I_d"
ACCELERATION_RADIUS = "acceleration_radius"
STIFFNESS_UNIFORMITY = "S_e"
STIFFNESS_FROBENIUS = "S_f"
STIFFNESS_VOLUME = "S_d"
TRANSLATIONAL_UNIFORMITY = "S_et"
ROTATIONAL_UNIFORMITY = "S_er"
TRANSLATIONAL_VOLUME = "S_da"
ROTATIONAL_VOLUME = "S_dd"
FREQUENCY_INDEX = "omega_n"
CRITICAL_MANIPULABILITY = "mu_v"
CRITICAL_CONDITION_NUMBER = "c_v"


class MetricInfo(NamedTuple):
    description: str
    unit: str


METRICS: dict[str, MetricInfo] = {
    MANIPULABILITY: MetricInfo("absolute manipulability |det J_m| (eq. 4.36, 4.38)", "m^3/rad^3"),
    CONDITION_NUMBER: MetricInfo("condition number of J_m (eq. 4.33)", "dimensionless"),
    POSITIONING_RESOLUTION: MetricInfo("positioning resolution ||J_m|| (eq. 4.30)", "m/rad"),
    INERTIA_VOLUME: MetricInfo("inertia volume det M_C (eq. 4.92-4.93)", "kg^3"),
    INERTIA_FROBENIUS: MetricInfo("inertia norm ||M_C||_F (eq. 4.98)", "kg"),
    INERTIA_UNIFORMITY: MetricInfo("inertia uniformity ||M_C|| ||M_C^-1|| (eq. 4.99)", "dimensionless"),
    DYNAMIC_MANIPULABILITY: MetricInfo("dynamic manipulability det(J_m M^-1) (eq. 4.97)", "1/(kg^3 m^3)"),
    ACCELERATION_RADIUS: MetricInfo("acceleration radius (eq. 4.96)", "1/(kg m)"),
    STIFFNESS_UNIFORMITY: MetricInfo("stiffness uniformity ||K_C|| ||K_C^-1|| (eq. 4.72)",
                                     "dimensionless (of the mixed-unit K_C in SI)"),
    STIFFNESS_FROBENIUS: MetricInfo("stiffness norm ||K_C||_F (eq. 4.73)", "mixed: N/m, N and N m/rad entries, in SI"),
    STIFFNESS_VOLUME: MetricInfo("stiffness volume det K_C (eq. 4.74)", "N^6/rad^3"),
    TRANSLATIONAL_UNIFORMITY: MetricInfo("translational stiffness uniformity (eq. 6.55)", "dimensionless"),
    ROTATIONAL_UNIFORMITY: MetricInfo("rotational stiffness uniformity (eq. 6.56)", "dimensionless"),
    TRANSLATIONAL_VOLUME: MetricInfo("translational stiffness volume det K_CA (eq. 6.74)", "N^3/m^3"),
    ROTATIONAL_VOLUME: MetricInfo("rotational stiffness volume det K_CD (eq. 6.75)", "N^3 m^3/rad^3"),
    FREQUENCY_INDEX: MetricInfo("natural frequency index ||M_C^-1 K_CA||_F (eq. 4.107)", "1/s^2"),
    CRITICAL_MANIPULABILITY: MetricInfo("critical manipulability l1 cos q_max, the least over the workspace (eq. 6.8)",
                                        "m/rad"),
    CRITICAL_CONDITION_NUMBER: MetricInfo("critical condition number 1 / cos^2 q_max, the largest over the workspace "
                                          "(eq. 6.18)", "dimensionless"),
}
"""Each metric's description (with its seed equation) and unit, by key."""
