"""The device as a static PNG for papers: links, bodies as bars, rigid plates, frame origins, mass centres and a
scale bar at one pose (matplotlib 3D)."""

from __future__ import annotations

import numpy as np

from hapticdesign.files import figure_bytes
from hapticdesign.analysis.view.skeleton import bars, frame_poses, links, mass_centres, plates, scale_length
from hapticdesign.model.device import Device


def render_png(device: Device, q: np.ndarray, dpi: int = 150) -> bytes:
    """PNG bytes of :func:`device_figure`."""
    import matplotlib.pyplot as plt

    fig = device_figure(device, q, dpi)
    png = figure_bytes(fig, "png")
    plt.close(fig)
    return png


def device_figure(device: Device, q: np.ndarray, dpi: int = 150):
    """A matplotlib figure of the device at pose ``q`` with equal axis scales (orthographic, z up)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    poses = frame_poses(device, q)
    origins = {name: pose[:3, 3] for name, pose in poses.items()}
    fig = plt.figure(figsize=(6.0, 5.0), dpi=dpi)
    ax = fig.add_subplot(projection="3d", proj_type="ortho")
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    for outline in plates(device, q):
        ax.add_collection3d(Poly3DCollection([[origins[name] for name in outline]], facecolor="#aab7c4",
                                             edgecolor="#34495e", alpha=0.45, linewidth=1.0))
    for parent, child in links(device):
        a, b = origins[parent], origins[child]
        ax.plot(*zip(a, b), color="#34495e", linewidth=1.0)
    ends = []
    for frame, end in bars(device):
        tip = (poses[frame] @ np.append(end, 1.0))[:3]
        ax.plot(*zip(origins[frame], tip), color="#2c3e50", linewidth=3.5, solid_capstyle="round")
        ends.append(tip)
    points = np.vstack([np.array(list(origins.values()))] + ([np.array(ends)] if ends else []))
    ax.scatter(*points.T, s=6, color="#7f8c8d", depthshade=False)
    bodies = mass_centres(device, poses)
    if bodies:
        masses = np.array([m for _, m, _ in bodies])
        centres = np.array([p for _, _, p in bodies])
        ax.scatter(*centres.T, s=20 + 160 * masses / masses.max(), color="#c82828", alpha=0.55, depthshade=False,
                   label="mass centres (area ~ mass)")
        points = np.vstack([points, centres])
    end = device.mechanism.end_effector
    if end is not None:
        ax.scatter(*origins[end], s=40, color="#e67e22", depthshade=False, label=f"end effector ({end})")
    low, high = points.min(axis=0), points.max(axis=0)
    half = 0.55 * max(float((high - low).max()), 1e-3)
    middle = 0.5 * (low + high)
    ax.set_xlim(middle[0] - half, middle[0] + half)
    ax.set_ylim(middle[1] - half, middle[1] + half)
    ax.set_zlim(middle[2] - half, middle[2] + half)
    ax.set_box_aspect((1, 1, 1))
    length = scale_length(2.0 * half)
    start = np.array([middle[0] - half, middle[1] - half, middle[2] - half])
    ax.plot([start[0], start[0] + length], [start[1]] * 2, [start[2]] * 2, color="black", linewidth=3.0)
    ax.text(start[0], start[1], start[2] + 0.04 * half, f"{length * 1000:g} mm", fontsize=8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.tick_params(labelsize=7)
    pose = ", ".join(f"{v:.3g}" for v in q)
    ax.set_title(f"{device.name[:60]}\nq = ({pose})", fontsize=9)
    if bodies or end is not None:
        ax.legend(loc="upper left", fontsize=7)
    return fig
