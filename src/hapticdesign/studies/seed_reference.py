"""The seeds' printed numbers that the studies put side by side with ours.

Seed 000 = Kizilbey (2019), seed 001 = Gorgulu (2018). Values are as printed
(OCR transcription checked against the seed text); where a printed value is known to be rounded or
mistyped the study says so next to it.
"""

from __future__ import annotations

import json
from importlib import resources

LEVELS = (0.0, 0.001, 0.01, 0.1, 1.0, 2.0)

# Seed 000 Table 4.4: maximum stable impedance of DOF 1, type 1 (range, mean, 1 sigma) [N m/rad].
TABLE_4_4 = {0.0: (8, 27, 10.96, 2.99), 0.001: (4, 26, 9.84, 2.85), 0.01: (4, 24, 9.60, 3.06),
             0.1: (4, 12, 6.23, 1.89), 1.0: (4, 11, 4.42, 1.07), 2.0: (4, 7, 4.20, 0.60)}

# Seed 000 Table 4.6: transparency bandwidth of DOF 1, type 1 (range, mean, 1 sigma) [Hz].
TABLE_4_6 = {0.0: (2.1, 2.3, 2.2, 0.1), 0.001: (2.1, 2.5, 2.2, 0.1), 0.01: (2.1, 2.4, 2.2, 0.1),
             0.1: (2.1, 2.8, 2.3, 0.1), 1.0: (2.6, 3.7, 3.1, 0.2), 2.0: (2.9, 4.0, 3.4, 0.2)}

# Seed 000 §4.1.4 (Figure 4.11) and §4.2.4 (Figure 4.21): share of designs whose type 1 and type 2
# results agree; the text gives the LN = 0, 0.001 and 2 values only.
AGREEMENT = {"impedance": {0.0: 1.00, 0.001: 0.54, 2.0: 0.08},
             "transparency": {0.0: 1.00, 0.001: 0.93, 2.0: 0.00}}

# Seed 000 Appendix B.1 (3 DOF) and B.2 (6 DOF): coefficients of the closed-form LN, as printed.
APPENDIX_B = [("phantom-3dof", {"Ixx2": 2}, 0.75), ("phantom-3dof", {"Ixx3": 2}, 1.375),
              ("phantom-3dof", {"Ixy2": 2}, 3.0), ("phantom-3dof", {"Ixy3": 2}, 5.0),
              ("phantom-3dof", {"Ixz3": 2}, 5.5), ("phantom-6dof", {"Ixx4": 2}, 6.15625),
              ("phantom-6dof", {"Ixx5": 2}, 11.6934), ("phantom-6dof", {"Ixx6": 2}, 22.665),
              ("phantom-6dof", {"Iyy5": 2}, 13.9062), ("phantom-6dof", {"Ixx4": 1, "Ixx5": 1}, 5.46875)]

# Seed 000 eq. 3.33 as printed (three significant digits): the analytic example of a linear design.
EQ_3_33 = {
    "m1": 0.25, "m2": 0.156, "m2a": 0.026, "m3": 0.031, "m3a": 0.242,
    "r1z": 0.15, "r2x": -0.091, "r2ax": 0.078, "r3z": -0.036, "r3az": -0.031,
    "Ixx1": 0.009, "Iyy1": 0.009, "Izz1": 0.00015,
    "Ixx2": 0.00982641, "Iyy2": 0.00488281, "Izz2": 0.00488281,
    "Ixx2a": 0.00488281, "Iyy2a": 0.00488281, "Izz2a": 0.00488281,
    "Ixx3": 0.00481407, "Iyy3": 0.00488281, "Izz3": 0.00488281,
    "Ixx3a": 0.00488281, "Iyy3a": 0.00488281, "Izz3a": 0.00488281,
}

# Seed 001, final design (Table 7.8) at home: Table 7.9 and eq. 7.6-7.13.
RCUBE_FINAL = {
    "link_mass_g": 77.7,             # Table 7.9
    "M_C_diagonal_kg": 0.0429,       # eq. 7.6
    "M_C_off_diagonal_kg": -0.0039,  # eq. 7.6
    "K_C_translational_N_per_m": 209110.0,   # eq. 7.7 diagonal
    "K_C_rotational_Nm_per_rad": 727.0,      # eq. 7.7 diagonal
    "K_C_coupling_N": 6495.0,                # eq. 7.7 entry (1, 6)
    "natural_frequencies_rad_s": (2113.3, 2113.3, 2442.7),  # eq. 7.11-7.13
    "max_deflection_mm": 0.07,       # Table 7.9 ("below")
    "q_max_deg": 32.5,               # Table 7.2
}

# Seed 001 Table 7.2, the two shortest solutions: link lengths l1, l2, l3 [mm].
TABLE_7_2_SHORTEST = [(1, 111.7, 74.1, 121.8), (2, 113.3, 74.4, 123.4)]

# Seed 001 Table 7.3 (solutions 1, 20, 40): link lengths [mm], manipulability mu_v, condition number c_v.
TABLE_7_3 = [(1, 111.7, 74.1, 121.8, 0.094, 1.406), (20, 121.5, 86.3, 129.3, 0.106, 1.322),
             (40, 149.8, 97.4, 134.8, 0.137, 1.191)]


def appendix_c_designs() -> list[dict]:
    """Seed 000 Appendix C: 30 printed designs, 5 per LN level (level, printed LN, parameters).

    Omitted parameters are zero; link 1 is not printed (it does not enter LN).
    """
    text = resources.files("hapticdesign.studies").joinpath("data/seed000_appendix_c_designs.json").read_text()
    return json.loads(text)
