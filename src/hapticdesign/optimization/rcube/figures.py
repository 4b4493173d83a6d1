"""Figures of the optimization chain (seed 001 Figures 7.1-7.4 and the Pareto fronts), PNG and SVG."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hapticdesign.files import save_figure


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, out_dir: Path, name: str) -> list[Path]:
    paths = []
    fig.tight_layout()
    for ext in ("png", "svg"):
        paths.append(save_figure(fig, out_dir / f"{name}.{ext}"))
    _pyplot().close(fig)
    return paths


def pareto_front_3d(F: np.ndarray, out_dir: Path, name: str = "pareto_front_synthesis") -> list[Path]:
    """The synthesis front in ``(O1, O2, O3)`` (eq. 6.82-6.84), coloured by ``O1``."""
    plt = _pyplot()
    fig = plt.figure(figsize=(6.5, 5), dpi=100)
    ax = fig.add_subplot(projection="3d")
    points = ax.scatter(F[:, 0], F[:, 1], F[:, 2] * 1e15, c=F[:, 0], cmap="viridis")
    ax.set_xlabel("O1 = tan q_max (-)")
    ax.set_ylabel("O2 = det M_C (kg^3)")
    ax.set_zlabel("O3 = 1/det K_CA (1e-15 m^3/N^3)")
    fig.colorbar(points, ax=ax, shrink=0.6, pad=0.12, label="O1 = tan q_max (dimensionless)")
    ax.set_title("Kinematic synthesis: Pareto front")
    return _save(fig, out_dir, name)


def selection_label(selected: int, weight: float) -> str:
    """Legend text of the selected solution: which rule picked it (§7.2, Table 7.5)."""
    return f"selected: solution {selected + 1} (least weighted RMS, weight {weight:g} on mu_vn*)"


def frequency_vs_manipulability(omega, mu, rms_choice: int, selected: int, weight: float, out_dir: Path) -> list[Path]:
    """Figure 7.1: ``omega_nn*`` against ``mu_vn*`` (eq. 7.1-7.4), with the least-RMS solution (Figure
    7.2's rule) and the selected one (the weighted rule of Table 7.5) marked."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5), dpi=100)
    ax.scatter(mu, omega, s=18, color="0.5", label="front solutions")
    ax.scatter([mu[rms_choice]], [omega[rms_choice]], s=70, facecolors="none", edgecolors="tab:blue",
               label=f"least RMS (Fig. 7.2): solution {rms_choice + 1}")
    ax.scatter([mu[selected]], [omega[selected]], marker="*", s=120, color="red", label=selection_label(selected, weight))
    ax.set_xlabel("normalized manipulability index mu_vn* (-)")
    ax.set_ylabel("normalized natural frequency index omega_nn* (-)")
    ax.legend(fontsize=8)
    ax.set_title("Figure 7.1: frequency against manipulability")
    return _save(fig, out_dir, "figure_7_1_frequency_vs_manipulability")


def rms_curves(curves: dict[str, np.ndarray], out_dir: Path, name: str, title: str, selected: int | None = None,
               weight: float = 0.0) -> list[Path]:
    """Figures 7.2-7.3: RMS of the normalized indices (eq. 7.2-7.4) against the solution number, one
    curve per weight, each with its least value marked; ``selected`` adds the solution the chain
    selected (by the weighted rule of Table 7.5) so that the figure says what was chosen and why."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.2), dpi=100)
    for label, values in curves.items():
        k = int(np.argmin(values))
        line, = ax.plot(np.arange(1, len(values) + 1), values, marker=".", label=f"{label} (least: solution {k + 1})")
        ax.scatter([k + 1], [values[k]], s=60, facecolors="none", edgecolors=line.get_color())
    if selected is not None:
        ax.axvline(selected + 1, color="red", linestyle="--", label=selection_label(selected, weight))
    ax.set_xlabel("solution number (front sorted by total link length)")
    ax.set_ylabel("RMS of normalized indices (-)")
    ax.legend(fontsize=8)
    ax.set_title(title)
    return _save(fig, out_dir, name)


def cross_section_figure(ratios, CS1n, CS2n, rms, chosen: float, out_dir: Path) -> list[Path]:
    """Figure 7.4: RMS against ``d/D`` (left) and the normalized Pareto curve (right)."""
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 4), dpi=100)
    k = int(np.argmin(rms))
    left.plot(ratios, rms)
    left.scatter([ratios[k]], [rms[k]], color="red", label=f"d/D = {chosen:.3f}")
    left.set_xlabel("d/D (-)")
    left.set_ylabel("RMS of normalized CS1, CS2 (-)")
    left.legend()
    right.plot(CS2n, CS1n, marker=".")
    right.scatter([CS2n[k]], [CS1n[k]], color="red")
    right.set_xlabel("CS2 = I_l, normalized (-)")
    right.set_ylabel("CS1 = 1/S_l, normalized (-)")
    fig.suptitle("Figure 7.4: cross-section ratio")
    return _save(fig, out_dir, "figure_7_4_cross_section")


def ply_front(F: np.ndarray, chosen: int, out_dir: Path, rule: str = "") -> list[Path]:
    """The ply front: translational deflection against the number of plies (Table 7.6); ``rule``
    says why the marked design was chosen."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 4), dpi=100)
    ax.scatter(F[:, 2], F[:, 0] * 1e3, s=18)
    label = f"chosen: solution {chosen + 1}" + (f" ({rule})" if rule else "")
    ax.scatter([F[chosen, 2]], [F[chosen, 0] * 1e3], color="red", label=label)
    ax.set_yscale("log")
    ax.set_xlabel("number of plies")
    ax.set_ylabel("CF1, translational deflection under 20 N (mm)")
    ax.legend(fontsize=8)
    ax.set_title("Composite plies: Pareto front")
    return _save(fig, out_dir, "pareto_front_plies")
