"""Figures of the optimization chain (seed 001 Figures 7.1-7.4 and the Pareto fronts), PNG and SVG."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, out_dir: Path, name: str) -> list[Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    fig.tight_layout()
    for ext in ("png", "svg"):
        path = out_dir / f"{name}.{ext}"
        fig.savefig(path)
        paths.append(path)
    _pyplot().close(fig)
    return paths


def pareto_front_3d(F: np.ndarray, out_dir: Path, name: str = "pareto_front_synthesis") -> list[Path]:
    """The synthesis front in ``(O1, O2, O3)`` (eq. 6.82-6.84)."""
    plt = _pyplot()
    fig = plt.figure(figsize=(6, 5), dpi=100)
    ax = fig.add_subplot(projection="3d")
    ax.scatter(F[:, 0], F[:, 1], F[:, 2] * 1e15, c=F[:, 0], cmap="viridis")
    ax.set_xlabel("O1 = tan q_max")
    ax.set_ylabel("O2 = det M_C (kg^3)")
    ax.set_zlabel("O3 = 1/det K_CA (1e-15 m^3/N^3)")
    ax.set_title("Kinematic synthesis: Pareto front")
    return _save(fig, out_dir, name)


def frequency_vs_manipulability(omega, mu, selected: int, out_dir: Path) -> list[Path]:
    """Figure 7.1: ``omega_nn*`` against ``mu_vn*``."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 4), dpi=100)
    ax.scatter(mu, omega, s=18)
    ax.scatter([mu[selected]], [omega[selected]], color="red", label=f"min RMS: solution {selected + 1}")
    ax.set_xlabel("normalized manipulability index mu_vn*")
    ax.set_ylabel("normalized natural frequency index omega_nn*")
    ax.legend()
    ax.set_title("Figure 7.1")
    return _save(fig, out_dir, "figure_7_1_frequency_vs_manipulability")


def rms_curves(curves: dict[str, np.ndarray], out_dir: Path, name: str, title: str) -> list[Path]:
    """Figures 7.2-7.3: RMS value against the solution number, one curve per weight."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
    for label, values in curves.items():
        k = int(np.argmin(values))
        ax.plot(np.arange(1, len(values) + 1), values, marker=".", label=f"{label} (min: {k + 1})")
    ax.set_xlabel("solution number")
    ax.set_ylabel("RMS")
    ax.legend()
    ax.set_title(title)
    return _save(fig, out_dir, name)


def cross_section_figure(ratios, CS1n, CS2n, rms, chosen: float, out_dir: Path) -> list[Path]:
    """Figure 7.4: RMS against ``d/D`` (left) and the normalized Pareto curve (right)."""
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 4), dpi=100)
    k = int(np.argmin(rms))
    left.plot(ratios, rms)
    left.scatter([ratios[k]], [rms[k]], color="red", label=f"d/D = {chosen:.3f}")
    left.set_xlabel("d/D")
    left.set_ylabel("RMS of normalized CS1, CS2")
    left.legend()
    right.plot(CS2n, CS1n, marker=".")
    right.scatter([CS2n[k]], [CS1n[k]], color="red")
    right.set_xlabel("CS2 (normalized)")
    right.set_ylabel("CS1 (normalized)")
    fig.suptitle("Figure 7.4")
    return _save(fig, out_dir, "figure_7_4_cross_section")


def ply_front(F: np.ndarray, chosen: int, out_dir: Path) -> list[Path]:
    """The ply front: translational deflection against the number of plies (Table 7.6)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 4), dpi=100)
    ax.scatter(F[:, 2], F[:, 0] * 1e3, s=18)
    ax.scatter([F[chosen, 2]], [F[chosen, 0] * 1e3], color="red", label="chosen")
    ax.set_yscale("log")
    ax.set_xlabel("number of plies")
    ax.set_ylabel("CF1, translational deflection (mm)")
    ax.legend()
    ax.set_title("Composite plies: Pareto front")
    return _save(fig, out_dir, "pareto_front_plies")
