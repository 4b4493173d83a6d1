"""``show`` draws a delta as a delta: the base triangle of hip pivots and the platform triangle as plates,
the parallelogram rods as bars, and a scale bar. Oracles: the delta's geometry as examples/devices/delta.yaml
states it (hips R = 36.6 mm from the axis 120 deg apart, platform corners r = 27.2 mm from its centre, rods
Lb = 102.5 mm whose two ends sit w/2 = 11.5 mm either side of the leg's middle line)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.analysis.view.skeleton import bars, export, frame_poses, home_pose, plates, scale_length
from hapticdesign.devices.device_file import load_device_file

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "devices"
R, RP, LB, W = 0.0366, 0.0272, 0.1025, 0.023


@pytest.fixture(scope="module")
def delta():
    device = load_device_file(EXAMPLES / "delta.yaml")
    q = home_pose(device)
    return device, q, frame_poses(device, q)


def _triangle(points) -> tuple[float, float]:
    """Circumradius and the largest deviation of a side from the mean side."""
    a, b, c = (np.linalg.norm(points[i] - points[(i + 1) % 3]) for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(points[1] - points[0], points[2] - points[0]))
    return a * b * c / (4 * area), max(a, b, c) - min(a, b, c)


def test_delta_plates_are_its_base_and_platform_triangles(delta):
    device, q, poses = delta
    found = {frozenset(outline): outline for outline in plates(device, q)}
    base = found[frozenset({"arm1", "arm2", "arm3"})]
    platform = found[frozenset({"end1", "end2", "end3"})]
    for outline, radius in ((base, R), (platform, RP)):
        circumradius, spread = _triangle([poses[name][:3, 3] for name in outline])
        assert circumradius == pytest.approx(radius, rel=1e-9) and spread < 1e-9


def test_delta_rods_are_bars_of_length_lb_ending_beside_the_platform_corner(delta):
    device, q, poses = delta
    ends = {frame: (poses[frame] @ np.append(end, 1.0))[:3] for frame, end in bars(device)}
    for leg in (1, 2, 3):
        corner = poses[f"end{leg}"][:3, 3]
        for side in "ab":
            frame = f"rod{leg}{side}"
            assert np.linalg.norm(ends[frame] - poses[frame][:3, 3]) == pytest.approx(LB, rel=1e-12)
            assert np.linalg.norm(ends[frame] - corner) == pytest.approx(W / 2, rel=1e-9)


def test_page_data_carries_plates_bars_and_a_round_scale(delta):
    device, q, _ = delta
    data = export(device, q)
    assert len(data["bars"]) == len(bars(device)) and data["plates"] == plates(device, q)
    assert data["scale"] == scale_length(data["extent"])


@pytest.mark.parametrize("extent", [0.013, 0.1, 0.35, 2.0, 7.5])
def test_scale_is_one_two_or_five_times_a_power_of_ten_within_a_quarter_of_the_extent(extent):
    length = scale_length(extent)
    mantissa = length / 10 ** math.floor(math.log10(length) + 1e-12)
    assert round(mantissa, 9) in (1.0, 2.0, 5.0)
    assert extent / 10 < length <= extent / 4


def test_rcube_has_no_ground_plate_through_its_three_axes():
    """The R-CUBE's chain bases lie on the three axes (seed 001 eq. 5.2), with the origin not coplanar."""
    device = load_device_file(EXAMPLES / "rcube.yaml")
    assert plates(device, home_pose(device)) == []
