"""Shared fixtures: presets, random physically consistent inertial parameters, headless Chromium."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

from hapticdesign.devices.registry import preset


EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "devices"


def pytest_configure(config):
    """With pytest-xdist workers (``-n``), compile the rendering loop here first, for a tree and for a closed-loop
    device, each with a joint and a Cartesian wall, and the closed-loop model's equations along a motion (the
    growth check's linearization), so that the workers load them from numba's cache instead of each compiling
    them (an empty cache costs one compile, not one per worker; a warm one milliseconds)."""
    if hasattr(config, "workerinput") or not config.getoption("numprocesses", None):
        return
    from hapticdesign.analysis.dynamics.device import mass_matrix
    from hapticdesign.analysis.view.skeleton import home_pose
    from hapticdesign.devices.device_file import load_device_file
    from hapticdesign.simulation.loop import warm_up

    five_bar = load_device_file(EXAMPLES / "five-bar.yaml")
    for device in (preset("phantom-3dof"), five_bar):
        warm_up(device)
    mass_matrix(five_bar, home_pose(five_bar))


@pytest.fixture(scope="session")
def phantom3():
    return preset("phantom-3dof")


@pytest.fixture(scope="session")
def phantom6():
    return preset("phantom-6dof")


def random_standard_parameters(rng: np.random.Generator, n_bodies: int) -> np.ndarray:
    """Standard parameters of random rigid bodies: a random positive definite pseudo-inertia each."""
    out = []
    for _ in range(n_bodies):
        a = rng.normal(size=(4, 4)) * np.array([0.05, 0.05, 0.05, 0.5])
        p = a @ a.T + 1e-4 * np.eye(4)
        sigma, h, m = p[:3, :3], p[:3, 3], p[3, 3]
        j = np.trace(sigma) * np.eye(3) - sigma
        out.append([m, *h, j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]])
    return np.array(out).ravel()


CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
DRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync")


def _chromium(logs: dict):
    """Debian's Chromium through Selenium, headless, with a fresh profile and the ``logs`` kept (yields the driver)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    if not (Path(CHROMIUM).exists() and Path(DRIVER).exists()):
        pytest.fail("chromium and chromedriver are needed (make browser installs them)")
    profile = tempfile.mkdtemp(prefix="hd-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", logs)
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


@pytest.fixture(scope="module")
def browser():
    """Debian's Chromium through Selenium, headless, with a fresh profile (``make browser`` installs it)."""
    yield from _chromium({"browser": "ALL"})


@pytest.fixture(scope="module")
def network_browser():
    """:func:`browser` that also logs every request the page makes (``driver.get_log("performance")``)."""
    yield from _chromium({"browser": "ALL", "performance": "ALL"})
