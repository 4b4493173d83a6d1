"""The R-CUBE report's picture of the device: each chain drawn from its base on its own axis at S = l1
(seed 001 eq. 5.2, 6.39) through links of Table 7.8's lengths (111.7, 74.1, 121.8 mm) to the platform at home,
the three chains meeting there."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from hapticdesign.analysis.rcube.design import final_design  # noqa: E402
from hapticdesign.studies.rcube import device_figure, device_step  # noqa: E402

LENGTHS = (0.1117, 0.0741, 0.1218)  # Table 7.8, m


def test_each_chain_is_drawn_with_table_7_8s_links_from_its_axis_to_the_platform():
    design = final_design()
    fig = device_figure(design)
    chains = {line.get_label(): np.array(line.get_data_3d()).T for line in fig.axes[0].lines
              if line.get_label().startswith("chain")}
    assert sorted(chains) == ["chain 1", "chain 2", "chain 3"]
    ends = []
    for k, name in enumerate(sorted(chains)):
        path = chains[name]
        assert np.linalg.norm(np.diff(path, axis=0), axis=1) == pytest.approx(LENGTHS, rel=1e-9)
        base = np.zeros(3)
        base[k] = LENGTHS[0]  # chain k's base sits on axis k at S = l1
        assert np.allclose(path[0], base, atol=1e-12)
        ends.append(path[-1])
    assert np.allclose(ends, [design.geometry.home] * 3, atol=1e-9)


def test_the_device_step_carries_the_picture():
    outcome = device_step(None)
    assert [f.name for f in outcome.figures] == ["rcube_device"]
    assert outcome.figures[0].png[:8] == b"\x89PNG\r\n\x1a\n"
