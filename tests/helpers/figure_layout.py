"""Layout checks of a drawn matplotlib figure, in pixels: what a reader would see as cut, squeezed or overlapping."""

from __future__ import annotations


def _boxes(fig):
    """Each axes' (maps and colour bars) tight box with its labels and title, as (name, Bbox) in display pixels."""
    renderer = fig.canvas.get_renderer()
    return [(ax.get_label() or f"axes {k}", ax.get_tightbbox(renderer)) for k, ax in enumerate(fig.axes)
            if ax.get_visible()]


def _overlap(a, b, slack: float = 1.0) -> bool:
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > slack) and (min(a.y1, b.y1) - max(a.y0, b.y0) > slack)


def tick_labels(ax, renderer):
    """The visible, non-empty tick labels of an axes (x, y and for 3D axes z), each with its box."""
    out = []
    axes = [ax.xaxis, ax.yaxis] + ([ax.zaxis] if hasattr(ax, "zaxis") else [])
    for axis in axes:
        labels = [t for t in axis.get_ticklabels() if t.get_visible() and t.get_text()]
        out.append([(t.get_text(), t.get_window_extent(renderer)) for t in labels])
    return out


TICK_GAP = 6.0
"""Pixels at least between two tick labels of one axis (closer, they read as one number: "-1000 100")."""


def layout_problems(fig, min_map_px: float = 0.0, maps=()) -> list[str]:
    """What is wrong with ``fig``'s layout once drawn: an axes (with its tick labels, axis labels and title) or a
    legend outside the figure, by any part of a pixel, or overlapping another; tick labels of one axis closer than
    :data:`TICK_GAP`; a map of ``maps`` narrower or lower than ``min_map_px``. Empty when it reads."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    width, height = fig.bbox.width, fig.bbox.height
    problems = []
    boxes = _boxes(fig) + [(f"legend {k}", legend.get_window_extent(renderer)) for k, legend in enumerate(fig.legends)]
    for name, box in boxes:
        if box.x0 < -0.5 or box.y0 < -0.5 or box.x1 > width + 0.5 or box.y1 > height + 0.5:
            problems.append(f"{name} leaves the figure: {box.bounds} in {width:.0f} x {height:.0f}")
    for i, (a, box_a) in enumerate(boxes):
        for b, box_b in boxes[i + 1:]:
            if _overlap(box_a, box_b):
                problems.append(f"{a} overlaps {b}")
    for k, ax in enumerate(fig.axes):
        for labels in tick_labels(ax, renderer):
            for i, (text_a, box_a) in enumerate(labels):
                for text_b, box_b in labels[i + 1:]:
                    if _overlap(box_a.padded(TICK_GAP / 2), box_b.padded(TICK_GAP / 2), slack=0.0):
                        problems.append(f"axes {k}: tick labels {text_a!r} and {text_b!r} collide")
    for ax in maps:
        box = ax.get_window_extent(renderer)
        if min(box.width, box.height) < min_map_px:
            problems.append(f"a map of {box.width:.0f} x {box.height:.0f} px (at least {min_map_px:g} wanted)")
    return problems
