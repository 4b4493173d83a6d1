"""Many designs through the compiled kernels (:mod:`hapticdesign.analysis.design_batch`) against one design at a
time (:func:`hapticdesign.analysis.metrics.indices.evaluate` of ``DesignSpace.device``, whose indices are checked
against closed forms, finite differences, kinetic energy and the VJM's own references in test_indices.py and
test_indices_force_stiffness.py): same values, same failures, for every kind of design variable, trees and closed
loops. An elastic post under the five-bar's loop (tests/devices/five_bar_on_a_post.yaml) is also checked against the
Euler-Bernoulli cantilever's closed form and the series law (tests/helpers/cantilever.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.metrics.indices import Request
from hapticdesign.analysis.workspace import Workspace
from hapticdesign.devices.design_space import design_space
from hapticdesign.errors import UserError
from hapticdesign.analysis.metrics.indices import evaluate, evaluate_designs

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "devices"
TUBES = ROOT / "examples" / "studies" / "five-bar-tubes.yaml"
INDICES = ["isotropy", "apparent_mass", "condition", "manipulability", "inertia_uniformity", "kmax",
           Request("kmax", {"period": 0.0005, "delay": 2, "wall_damping": 0.05}, "kmax_damped")]
KEYS = [r if isinstance(r, str) else r.key for r in INDICES]
CASES = {
    "five-bar": (["l1", "l2", "d"], Workspace((0.0, 0.0, 0.18), (0.06, 0.0, 0.06), 3),
                 {"l1": (0.08, 0.13), "l2": (0.12, 0.17), "d": (0.05, 0.1)}),
    "delta": (["La", "Lb", "R"], Workspace((-0.10, 0.0, 0.0), (0.03, 0.03, 0.03), 2),
              {"La": (0.05, 0.07), "Lb": (0.09, 0.11), "R": (0.03, 0.04)}),
}


def _same(space, designs, points, requests, keys):
    """The batched evaluation of ``designs`` equals the one-design path's, design by design (values to 1e-9,
    failures alike); returns the batched answers."""
    batched = evaluate_designs(space, designs, points, requests)
    assert space.cache.get("batch"), "the compiled path serves these indices and variables"
    for values, fast in zip(designs, batched):
        try:
            slow = evaluate(space.device(values), points, requests)
        except Exception as exc:  # noqa: BLE001 - the design's device is refused: the batch says so too
            assert fast.reason is not None and str(exc) in fast.reason, (fast.reason, exc)
            continue
        assert (fast.reason is None) == (slow.reason is None), (fast.reason, slow.reason)
        for key in keys if slow.reason is None else ():
            np.testing.assert_allclose(fast.values[key], slow.values[key], rtol=1e-9, err_msg=key)
    return batched


@pytest.mark.parametrize("name", sorted(CASES))
def test_batched_designs_equal_one_design_at_a_time(name):
    names, workspace, bounds = CASES[name]
    space = design_space(EXAMPLES / f"{name}.yaml", names)
    rng = np.random.default_rng(7)
    designs = [{k: float(rng.uniform(*bounds[k])) for k in names} for _ in range(6)]
    _same(space, designs, workspace.points(), INDICES, KEYS)


TUBE_INDICES = ["isotropy", "apparent_mass", "mass", "force", Request("force", {"torque": "peak"}, "peak"),
                "stiffness", "frequency", "kmax"]
TUBE_KEYS = [r if isinstance(r, str) else r.key for r in TUBE_INDICES]


def test_every_variable_kind_follows_each_design():
    """Geometry with tube bodies (masses follow the lengths), sections (masses and K_C follow), a point mass, and
    every motor field (discrete gear ratios, rotor inertia, damping, torques): each design's values are its own
    device's, and they differ from design to design (so the file's inertial parameters, B or torques would not
    pass)."""
    names = ["l1", "l2", "d", "links.prox1.D", "links.dist2.d", "mh", "rhz", "actuators.q1.gear_ratio",
             "actuators.q2.gear_ratio", "actuators.q1.rotor_inertia", "actuators.q2.damping",
             "actuators.q1.torque_continuous", "actuators.q2.torque_peak", "actuators.q1.torque_peak"]
    space = design_space(TUBES, names)
    rng = np.random.default_rng(11)
    designs = [{"l1": rng.uniform(0.08, 0.13), "l2": rng.uniform(0.12, 0.17), "d": rng.uniform(0.05, 0.1),
                "links.prox1.D": rng.uniform(0.009, 0.02), "links.dist2.d": rng.uniform(0.004, 0.009),
                "mh": rng.uniform(0.005, 0.05), "rhz": rng.uniform(0.0, 0.02),
                "actuators.q1.gear_ratio": float(rng.choice([5.0, 13.3])),
                "actuators.q2.gear_ratio": float(rng.choice([5.0, 13.3])),
                "actuators.q1.rotor_inertia": rng.uniform(5e-7, 3e-6), "actuators.q2.damping": rng.uniform(0, 0.01),
                "actuators.q1.torque_continuous": rng.uniform(0.01, 0.05),
                "actuators.q2.torque_peak": rng.uniform(0.05, 0.1), "actuators.q1.torque_peak": rng.uniform(0.05, 0.1)}
               for _ in range(5)]
    points = Workspace((0.0, 0.0, 0.16), (0.04, 0.0, 0.04), 3).points()
    batched = _same(space, designs, points, TUBE_INDICES, TUBE_KEYS)
    valid = [b for b in batched if b.reason is None]
    assert len(valid) >= 3
    for key in TUBE_KEYS:
        firsts = [b.values[key][0] for b in valid]
        assert len(set(np.round(firsts, 12))) == len(firsts), key


def test_a_tree_goes_through_the_same_batch():
    """A tree (the Phantom with its motors, a coupled one among them, and joint limits) is a closed-loop device
    without loops: geometry, inertial parameters and motor fields through the compiled batch, as design by design;
    a design beyond a joint limit fails the same way."""
    names = ["l2", "l3", "m2", "m3a", "Ixx3a", "actuators.theta1.gear_ratio", "actuators.2.rotor_inertia",
             "actuators.theta2.damping"]
    space = design_space(EXAMPLES / "phantom-3dof-motors.yaml", names)
    home = np.array([0.12327604, 0.01236886, 0.08727412])
    points = home + np.array([[0.0, 0.0, 0.0], [0.02, 0.0, 0.01], [-0.02, 0.02, 0.0], [0.0, -0.02, -0.02]])
    rng = np.random.default_rng(3)
    designs = [{"l2": rng.uniform(0.19, 0.24), "l3": rng.uniform(0.15, 0.2), "m2": rng.uniform(0.1, 0.2),
                "m3a": rng.uniform(0.2, 0.3), "Ixx3a": rng.uniform(0.0045, 0.0055),
                "actuators.theta1.gear_ratio": float(rng.choice([10.0, 13.3])),
                "actuators.2.rotor_inertia": rng.uniform(5e-7, 2e-6),
                "actuators.theta2.damping": rng.uniform(0.0, 0.001)} for _ in range(5)]
    designs.append({"l2": 0.215, "m2": -1.0})  # refused by the file's checks
    designs.append({"l2": 0.12, "l3": 0.12})  # reaches the points only beyond a joint limit, or not at all
    batched = _same(space, designs, points, INDICES + ["mass"], KEYS + ["mass"])
    assert sum(b.reason is None for b in batched) == 5
    assert "negative mass" in batched[5].reason


def test_refused_designs_say_why_in_the_batch():
    space = design_space(TUBES, ["l1", "links.prox1.D", "links.prox1.d", "actuators.q1.gear_ratio"])
    points = Workspace((0.0, 0.0, 0.16), (0.02, 0.0, 0.02), 2).points()
    designs = [{"l1": 0.1, "links.prox1.D": 0.008, "links.prox1.d": 0.009},
               {"l1": 0.1, "actuators.q1.gear_ratio": -2.0},
               {"l1": 0.0},
               {"l1": 0.1}]
    fast = _same(space, designs, points, ["apparent_mass", "stiffness"], ["apparent_mass", "stiffness"])
    assert "link prox1: inner diameter d" in fast[0].reason
    assert "gear_ratio" in fast[1].reason
    assert "zero length" in fast[2].reason
    assert fast[3].reason is None


def test_batched_failures_name_the_point_or_the_design():
    space = design_space(EXAMPLES / "five-bar.yaml", ["l1", "l2"])
    points = np.array([[0.0, 0.0, 0.18], [0.0, 0.0, 0.235], [0.0, 0.0, 0.30]])
    designs = [{"l1": 0.10, "l2": 0.14}, {"l1": 0.02, "l2": 0.03}, {"l1": 0.10, "l2": float("nan")}]
    fast = evaluate_designs(space, designs, points, ["isotropy"])
    slow = evaluate(space.device(designs[0]), points, ["isotropy"])
    assert "(0, 0, 0.3) m" in fast[0].reason and "(0, 0, 0.3) m" in slow.reason
    assert "cannot close" in fast[1].reason
    assert "finite" in fast[2].reason


def test_a_way_across_a_working_mode_singularity_is_refused_one_design_and_batched():
    """The Phantom's handle taken straight from home (in front of the base axis, theta1 = 0) to the point mirrored
    behind that axis: along the straight way the arm would swing over the axis (theta1 kept, the shoulder's working
    mode changed: det(U^T J_v) changes sign where the handle crosses the axis). The inverse kinematics keeps the
    working mode of its start, so the point is refused, by the one IK and by the batch alike; the same point is
    reached on home's working mode by a way around the axis, where the handle stays in front of the shoulder
    along theta1's azimuth (the closed-form sign of the arm's reach, independent of the IK's determinant test)."""
    space = design_space(EXAMPLES / "phantom-3dof.yaml", ["l2"])
    device = space.base
    home = configuration_of(device).pose(np.zeros(3))[:3, 3]
    assert home[0] > 0.1 and abs(home[1]) < 1e-12
    behind = np.array([-0.6 * home[0], 0.0, home[2]])
    with pytest.raises(UserError, match="behind a singularity"):
        configuration_of(device).reach(behind[None])
    batched = evaluate_designs(space, [{"l2": device.params["l2"]}], behind[None], ["isotropy"])[0]
    assert space.cache.get("batch") and "behind a singularity" in batched.reason
    radius = np.hypot(home[0], home[1])
    around = [radius * np.array([np.cos(a), np.sin(a), 0.0]) + [0.0, 0.0, home[2]] for a in np.linspace(0, np.pi, 19)]
    q_a, _ = configuration_of(device).reach(np.array([*around, behind]))
    reached = configuration_of(device).pose(q_a[-1])[:3, 3]
    np.testing.assert_allclose(reached, behind, atol=1e-9)
    azimuth = np.array([np.cos(q_a[-1, 0]), np.sin(q_a[-1, 0]), 0.0])
    assert reached @ azimuth > 0.1


def test_an_index_the_device_cannot_give_fails_each_design_as_design_by_design():
    space = design_space(EXAMPLES / "five-bar.yaml", ["l1", "l2"])
    points = np.array([[0.0, 0.0, 0.18]])
    designs = [{"l1": 0.10, "l2": 0.14}, {"l1": 0.11, "l2": 0.15}]
    for request in ("force", "stiffness"):
        fast = evaluate_designs(space, designs, points, [request])
        slow = [evaluate(space.device(v), points, [request]) for v in designs]
        assert [f.reason for f in fast] == [s.reason for s in slow]
        assert all(s.reason for s in slow)
    assert evaluate_designs(space, [], points, ["isotropy"]) == []


def test_a_home_given_as_a_handle_position_follows_each_design_batched_as_one_at_a_time():
    """Issue 35: a device file whose home is a handle position (``home: {position}``) puts each design's home there
    (design by design: ``DesignSpace.device``, the file's own inverse kinematics). The batch reaches it first: a
    design that cannot reach the home position fails batched too (it reaches the workspace points, so reaching
    them from the file's home joint values would pass it), and the others give the same values."""
    data = yaml.safe_load((EXAMPLES / "five-bar.yaml").read_text())
    data["home"] = {"position": [0.0, 0.0, 0.22]}
    space = design_space(data, ["l1", "l2", "d"])
    short = {"l1": 0.09, "l2": 0.10, "d": 0.08}  # |A1 - home| = 0.2236 m > l1 + l2 = 0.19 m
    designs = [short, {"l1": 0.11, "l2": 0.15, "d": 0.07}, {"l1": 0.10, "l2": 0.16, "d": 0.05}]
    points = np.array([[0.0, 0.0, 0.15], [0.02, 0.0, 0.16], [-0.015, 0.0, 0.17]])  # within 0.19 m of both motors
    batched = evaluate_designs(space, designs, points, ["isotropy", "apparent_mass", "kmax"])
    assert space.cache.get("batch")
    with pytest.raises(UserError, match="home.position"):
        space.device(short)
    assert batched[0].reason.startswith("the handle cannot reach its home position (0, 0, 0.22) m")
    for values, fast in zip(designs[1:], batched[1:]):
        slow = evaluate(space.device(values), points, ["isotropy", "apparent_mass", "kmax"])
        assert fast.reason is None and slow.reason is None
        for key in slow.values:
            np.testing.assert_allclose(fast.values[key], slow.values[key], rtol=1e-9, err_msg=key)


POST = ROOT / "tests" / "devices" / "five_bar_on_a_post.yaml"
"""The five-bar of elastic tubes on an elastic post: the post's end (``top``) is ahead of both ends of the closure."""
E_POST, G_POST = 2.0e11, 8.0e10  # the post's moduli as the fixture file gives them (Pa)
POST_POINTS = np.array([[x, -0.03, z] for x in (0.033, 0.053) for z in (0.44, 0.46)])
"""Handle positions about the fixture's home (the five-bar's plane is y = oy = -0.03 m)."""
POST_DESIGNS = [{"links.post.D": 0.006, "ox": 0.04}, {"links.post.D": 0.009, "ox": 0.035},
                {"links.post.D": 0.0045, "ox": 0.046}]


def _post_fixture(tmp_path: Path, keep: set[str]) -> Path:
    """The fixture file with only the elastic links ``keep``; a body that was a dropped link becomes a point mass on
    the link's start frame (masses do not enter the stiffness)."""
    data = yaml.safe_load(POST.read_text())
    start = {link["name"]: link["from"] for link in data["links"]}
    data["links"] = [link for link in data["links"] if link["name"] in keep]
    data["bodies"] = [body if body.get("link", next(iter(keep))) in keep else
                      {"name": body["name"], "frame": start[body["link"]], "m": 0.05, "rx": 0.05}
                      for body in data["bodies"]]
    path = tmp_path / f"post-{'-'.join(sorted(keep))}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _post_compliance(design: dict, point: np.ndarray, height: float = 0.25) -> np.ndarray:
    """The closed form of the post alone at the handle: the steel rod's cantilever end compliance (its axis the
    base's z, ``height`` long) carried rigidly to the handle at ``point``."""
    from tests.helpers.cantilever import cantilever_compliance, carried_compliance, rod_rigidities

    top = np.array([0.0, 0.0, height])
    rigid = rod_rigidities(E_POST, G_POST, design["links.post.D"])
    return carried_compliance(cantilever_compliance(top, *rigid), point - top)


def _batched_stiffness(path: Path, designs: list[dict]):
    """The compiled path's ``K_C`` (D, P, 6, 6) of ``designs`` at :data:`POST_POINTS`, its actuated poses and its
    design space."""
    from hapticdesign.analysis.design_batch import DesignBatch

    space = design_space(path, sorted(designs[0]))
    batch = DesignBatch(space.base)
    got = batch.evaluate(space.batch_values(designs, batch), POST_POINTS, stiffness=True)
    assert got.ok.all(), got.reasons
    return got.stiffness, got.q, space


def _same_matrix(found: np.ndarray, expected: np.ndarray, rtol: float) -> None:
    """Equal to ``rtol`` of the largest entry (entries span five decades)."""
    np.testing.assert_allclose(found, expected, rtol=rtol, atol=rtol * np.abs(expected).max())


def test_an_elastic_post_under_a_closed_loop_is_the_cantilevers_closed_form_batched(tmp_path):
    """Only the post elastic, the five-bar rigid (its motors locked): a deformation of the post moves the whole loop
    rigidly and opens no closure, so the handle's compliance is the post's cantilever end compliance carried to the
    handle (Euler-Bernoulli closed form, tests/helpers/cantilever.py), for each design (the post's diameter, the
    loop's offset from the post) and point. The compiled batch and the one-design VJM both give it; a closure row
    that counts the post's twist at the second frame with the wrong sign (its value at both ends added, not
    subtracted) would have the post open the loop."""
    from hapticdesign.analysis.stiffness.device import cartesian_stiffness

    path = _post_fixture(tmp_path, {"post"})
    batched, q, space = _batched_stiffness(path, POST_DESIGNS)
    for d, design in enumerate(POST_DESIGNS):
        device = space.device(design)
        for p, point in enumerate(POST_POINTS):
            expected = np.linalg.inv(_post_compliance(design, point))
            _same_matrix(batched[d, p], expected, 1e-8)
            _same_matrix(cartesian_stiffness(device, q[d, p]), expected, 1e-8)


def test_an_elastic_post_is_in_series_with_the_elastic_loop_on_it_batched(tmp_path):
    """The post and the five-bar's four tubes elastic: the post carries the whole wrench and moves the loop rigidly,
    so the handle's compliance is the five-bar's on a rigid post (the one-design VJM of the fixture without the post's
    link) plus the post's closed form carried to the handle (springs in series). The compiled batch of the whole
    fixture equals that sum and the one-design VJM of the whole fixture, design by design (the post's and a distal
    tube's diameters, the loop's offset) and point by point."""
    from hapticdesign.analysis.stiffness.device import cartesian_stiffness

    designs = [{**design, "links.dist1.D": dist} for design, dist in zip(POST_DESIGNS, (0.010, 0.0085, 0.012))]
    batched, q, space = _batched_stiffness(POST, designs)
    loop_only = design_space(_post_fixture(tmp_path, {"prox1", "prox2", "dist1", "dist2"}), ["links.dist1.D", "ox"])
    for d, design in enumerate(designs):
        whole = space.device(design)
        rigid_post = loop_only.device({k: v for k, v in design.items() if k != "links.post.D"})
        for p, point in enumerate(POST_POINTS):
            _same_matrix(batched[d, p], cartesian_stiffness(whole, q[d, p]), 1e-9)
            series = np.linalg.inv(cartesian_stiffness(rigid_post, q[d, p])) + _post_compliance(design, point)
            _same_matrix(batched[d, p], np.linalg.inv(series), 1e-8)
