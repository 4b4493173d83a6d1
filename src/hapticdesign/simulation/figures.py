"""Campaign figures (seed 000 Figures 4.9-4.11, 4.18-4.21), PNG and SVG, matplotlib Agg backend."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hapticdesign.files import save_figure  # noqa: E402

MIN_RELATIVE_SPAN = 0.1  # a value axis spans at least this share of the values' mean magnitude
LABELS = {"impedance": ("Maximum stable impedance [N m/rad]", "k_max"),
          "transparency": ("Transparency bandwidth [Hz]", "bandwidth")}


def _save(fig, path: Path) -> None:
    for suffix in (".png", ".svg"):
        save_figure(fig, path.with_suffix(suffix), dpi=120, bbox_inches="tight")
    plt.close(fig)


def _save_atomically(fig, path: Path) -> list[Path]:
    """PNG and SVG of ``fig`` through :func:`hapticdesign.files.write_atomically` (one-line errors)."""
    written = []
    for suffix in (".png", ".svg"):
        written.append(save_figure(fig, path.with_suffix(suffix), dpi=120, bbox_inches="tight"))
    plt.close(fig)
    return written


def swarm_offsets(values: np.ndarray, width: float = 0.35, resolution: float | None = None) -> np.ndarray:
    """Horizontal offsets that spread (near-)equal values symmetrically, beeswarm style."""
    values = np.asarray(values, dtype=float)
    if resolution is None:
        span = np.nanmax(values) - np.nanmin(values) if values.size else 0.0
        resolution = span / 40 if span > 0 else 1.0
    bins = np.round(values / resolution)
    offsets = np.zeros_like(values)
    for b in np.unique(bins[np.isfinite(bins)]):
        idx = np.nonzero(bins == b)[0]
        k = len(idx)
        step = min(0.04, 2 * width / max(k, 1))
        offsets[idx] = (np.arange(k) - (k - 1) / 2) * step
    return offsets


def value_limits(values, relative: float = MIN_RELATIVE_SPAN) -> tuple[float, float] | None:
    """Axis limits that span at least ``relative`` of the values' mean magnitude, centred on their range (None when
    the values already span more, or there are none): a spread of a fraction of a percent, round-off or the
    resolution of a search, is then drawn flat instead of as a trend across the whole axis."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    if finite.size == 0:
        return None
    low, high = float(finite.min()), float(finite.max())
    span = relative * float(np.abs(finite).mean())
    if high - low >= span or span == 0.0:
        return None
    middle = 0.5 * (low + high)
    return middle - 0.5 * span, middle + 0.5 * span


def _floor_span(ax, values) -> str:
    """Apply :func:`value_limits` to ``ax``'s y axis; the caption's words for it when it applied."""
    limits = value_limits(values)
    if limits is None:
        return ""
    ax.set_ylim(*limits)
    return f"; axis spans {100 * MIN_RELATIVE_SPAN:.0f} % of the mean, the values' spread is smaller"


def _levels(designs) -> list[float]:
    return sorted({d.level for d in designs})


def _values(designs, cases, criterion, sim_type):
    return np.array([np.nan if cases[(d.name, criterion, sim_type)]["value"] is None
                     else cases[(d.name, criterion, sim_type)]["value"] for d in designs], dtype=float)


def beeswarm(designs, cases, criterion: str, path: Path) -> None:
    """Type 1 values per level with mean and 1 sigma (Figures 4.9, 4.19)."""
    ylabel, _ = LABELS[criterion]
    levels = _levels(designs)
    fig, ax = plt.subplots(figsize=(7, 4))
    shown = []
    for x, level in enumerate(levels):
        members = [d for d in designs if d.level == level]
        v = _values(members, cases, criterion, 1)
        shown.append(v)
        ax.scatter(x + swarm_offsets(v), v, s=14, facecolors="none", edgecolors="tab:blue")
        finite = v[np.isfinite(v)]
        if finite.size:
            sd = finite.std(ddof=1) if finite.size > 1 else 0.0
            ax.errorbar(x + 0.42, finite.mean(), yerr=sd, fmt="s", color="tab:red", capsize=4)
    ax.set_xticks(range(len(levels)), [f"{lv:g}" for lv in levels])
    ax.set_xlabel("Linearity Number")
    ax.set_ylabel(ylabel)
    span = _floor_span(ax, np.concatenate(shown) if shown else [])
    ax.set_title(f"{ylabel.split(' [')[0]} vs LN, type 1 (mean and 1 sigma in red{span})", fontsize=10)
    _save(fig, path)


def type_comparison(designs, cases, criterion: str, path: Path) -> None:
    """Type 1 and type 2 per design, one panel per level (Figures 4.10, 4.20)."""
    ylabel, _ = LABELS[criterion]
    levels = _levels(designs)
    cols = min(3, len(levels))
    rows = int(np.ceil(len(levels) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3 * rows), squeeze=False)
    for ax, level in zip(axes.ravel(), levels):
        members = [d for d in designs if d.level == level]
        x = np.arange(1, len(members) + 1)
        one, two = _values(members, cases, criterion, 1), _values(members, cases, criterion, 2)
        ax.plot(x, one, "o", mfc="none", label="type 1")
        ax.plot(x, two, "x", label="type 2")
        flat = _floor_span(ax, np.concatenate([one, two]))
        flat = f" (axis: {100 * MIN_RELATIVE_SPAN:.0f} % of the mean)" if flat else ""
        ax.set_title(f"LN = {level:g}{flat}", fontsize=9)
        ax.set_xlabel("design")
        ax.set_ylabel(ylabel)
    for ax in axes.ravel()[len(levels):]:
        ax.axis("off")
    axes[0, 0].legend()
    fig.tight_layout()
    _save(fig, path)


def agreement_bars(summary, criterion: str, path: Path) -> None:
    """Designs with the same and with different type 1 / type 2 results per level (Figures 4.11, 4.21)."""
    rows = [r for r in summary if r["criterion"] == criterion and r["type"] == 1]
    levels = [r["level"] for r in rows]
    same = np.array([r["agreement_share"] * r["n"] for r in rows])
    total = np.array([r["n"] for r in rows])
    x = np.arange(len(levels))
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.bar(x - 0.2, same, 0.4, label="same")
    ax.bar(x + 0.2, total - same, 0.4, label="different")
    ax.set_xticks(x, [f"{lv:g}" for lv in levels])
    ax.set_xlabel("Linearity Number")
    ax.set_ylabel("number of designs")
    ax.set_title(f"{LABELS[criterion][0].split(' [')[0]}: type 1 vs type 2")
    ax.legend()
    _save(fig, path)


def frequency_responses(designs, cases, path: Path) -> None:
    """|G_T| against frequency for the first design of each level, type 1 (Figure 4.18)."""
    fig, ax = plt.subplots(figsize=(7, 4))
    for level in _levels(designs):
        d = next(d for d in designs if d.level == level)
        case = cases[(d.name, "transparency", 1)]
        ax.plot(case["frequency"], case["g_t_db"], label=f"{d.name} (LN = {level:g})")
    for edge in (3.0, -3.0):
        ax.axhline(edge, color="grey", linestyle="--", linewidth=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|G_T| [dB]")
    ax.legend(fontsize=7)
    _save(fig, path)


def write_all(designs, cases, summary, folder: Path) -> None:
    for criterion in ("impedance", "transparency"):
        beeswarm(designs, cases, criterion, folder / f"{criterion}_beeswarm_type1")
        type_comparison(designs, cases, criterion, folder / f"{criterion}_type1_vs_type2")
        agreement_bars(summary, criterion, folder / f"{criterion}_agreement")
    frequency_responses(designs, cases, folder / "transparency_frequency_response")


def zwidth_chart(zw, title: str, path: Path, units: tuple[str, str] = ("N m s/rad", "N m/rad")) -> list[Path]:
    """The Z-width (Colgate & Brown 1994): stable (B, K) below the exact boundary, with the passivity
    bound and the short-delay linear approximation beside it; written atomically as PNG and SVG.
    ``units`` of B and K (a joint's by default; N s/m and N/m at a Cartesian wall)."""
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    ax.fill_between(zw.B, 0, zw.K, color="tab:blue", alpha=0.15, label="stable (exact, discrete time)")
    ax.plot(zw.B, zw.K, "-", color="tab:blue", lw=1.8, label="K_max(B), exact")
    if zw.passivity is not None:
        ax.plot(zw.B, zw.passivity, "--", color="tab:red", label="passivity: b > K (T/2 + N T) + |B|")
        ax.plot(zw.B, zw.linear, ":", color="k", label="linear approximation 2 (b + B) / (T (1 + 2 N))")
    top = max(max(zw.K), 1e-12)
    ax.set_ylim(0, 1.15 * top)
    ax.set_xlabel(f"virtual damping B [{units[0]}]")
    ax.set_ylabel(f"virtual stiffness K [{units[1]}]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    return _save_atomically(fig, path)


def robustness_chart(rows: list[dict], path: Path, sim_type: int = 2) -> list[Path]:
    """Mean relative change of the stable range against the modelling error, one line per LN level, with
    the 95 % confidence interval of the mean as error bars."""
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for level in sorted({r["level"] for r in rows}):
        chosen = sorted((r for r in rows if r["level"] == level), key=lambda r: r["error_percent"])
        mean = np.array([100 * (r["mean_relative_change"] or 0.0) for r in chosen])
        low = np.array([m if r["relative_change_ci_low"] is None else 100 * r["relative_change_ci_low"]
                        for r, m in zip(chosen, mean)])
        high = np.array([m if r["relative_change_ci_high"] is None else 100 * r["relative_change_ci_high"]
                         for r, m in zip(chosen, mean)])
        ax.errorbar([r["error_percent"] for r in chosen], mean, yerr=[mean - low, high - mean], fmt="o-", capsize=3,
                    label=f"LN = {level:g}")
    ax.set_xlabel("modelling error of masses and inertias [%] (seeded random signs)")
    ax.set_ylabel("mean |K_max - K_max(0)| / K_max(0) [%]")
    ax.set_title(f"Stable impedance range under modelling error, type {sim_type} (95 % CI)", fontsize=10)
    ax.legend(fontsize=8)
    return _save_atomically(fig, path)


ROUND_OFF = 1e-12


def colour_scale(values: np.ndarray) -> tuple[float, float, list[float] | None]:
    """Colour limits of a map and its ticks (None: the colour bar's own). A map whose values differ by less
    than ``ROUND_OFF`` of the largest is constant (its spread is round-off, not data): one tick at its value
    and limits 0.1 % either side, so the colour bar does not spread 1e-15 differences over its length."""
    finite = np.asarray(values, dtype=float)[np.isfinite(values)]
    if finite.size == 0:
        return 0.0, 1.0, None
    lo, hi = float(finite.min()), float(finite.max())
    if hi - lo > ROUND_OFF * max(abs(lo), abs(hi)):
        return lo, hi, None
    value = float(np.mean(finite))
    half = 1e-3 * abs(value) or 1.0
    return value - half, value + half, [value]


def stiffness_map_chart(result, joint_names: list[str], wall_name: str, path: Path) -> list[Path]:
    """Heat map of the largest stable stiffness over two joints' angles."""
    fig, ax = plt.subplots(figsize=(5.8, 4.6))
    values = np.array(result.K, dtype=float)
    lo, hi, ticks = colour_scale(values)
    image = ax.pcolormesh(result.second, result.first, values, shading="nearest", cmap="viridis", vmin=lo, vmax=hi)
    bar = fig.colorbar(image, ax=ax, label=f"K_max of {wall_name} [N m/rad]")
    bar.formatter.set_useOffset(False)
    if ticks is not None:
        bar.set_ticks(ticks, labels=[f"{t:.6g} (constant)" for t in ticks])
    bar.update_ticks()
    ax.set_xlabel(f"{joint_names[1]} [rad]")
    ax.set_ylabel(f"{joint_names[0]} [rad]")
    ax.set_title(f"Largest stable stiffness of {wall_name}, other joints held", fontsize=10, pad=12)
    return _save_atomically(fig, path)
