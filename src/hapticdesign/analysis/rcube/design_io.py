"""R-CUBE designs from command-line values or a YAML/JSON design file.

File keys (SI units): ``l1, l2, l3`` (m), optional ``offset`` (m), ``sigma``, ``density``
(kg/m^3), ``links``: three entries ``{D, d, plies: [a, b, c, d]}`` (plies at 0, 90, -45 and
45 degrees of M55J) or ``{D, d, E, G}`` (isotropic, Pa), and ``joints``: one entry for every joint
or a list of five (joints ``phi_i1 .. phi_i5``, eq. 5.5-5.14), each ``{rotational, translational,
torsional}`` in N m/rad, N/m, N m/rad (any omitted: rigid; ``torsional`` defaults to ``rotational``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured, read_text
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.analysis.rcube.design import FINAL_DENSITY, JOINT_NAMES, RIGID_JOINTS, RCubeDesign, final_design
from hapticdesign.analysis.stiffness.joints import JointStiffness
from hapticdesign.analysis.stiffness.link import LinkDesign
from hapticdesign.analysis.stiffness.materials import isotropic, laminate
from hapticdesign.analysis.stiffness.sections import Tube


def _number(entry: Mapping, key: str, where: str) -> float:
    if key not in entry:
        raise UserError(f"{where}: missing {key!r}")
    try:
        return float(entry[key])
    except (TypeError, ValueError):
        raise UserError(f"{where}: {key} must be a number, got {entry[key]!r}") from None


def link_from_mapping(entry: Mapping, density: float, where: str) -> LinkDesign:
    """One link: a tube plus either ply counts (M55J laminate) or isotropic ``E`` and ``G``."""
    tube = Tube(_number(entry, "D", where), _number(entry, "d", where))
    if "plies" in entry:
        moduli = laminate(tuple(entry["plies"]))
    elif "E" in entry:
        moduli = isotropic(_number(entry, "E", where), _number(entry, "G", where) if "G" in entry else None)
    else:
        raise UserError(f"{where}: give 'plies' (M55J laminate) or 'E' (isotropic material)")
    return LinkDesign(tube, moduli, float(entry.get("density", density)))


JOINT_KEYS = ("rotational", "translational", "torsional")


def joint_from_mapping(entry: Mapping, where: str) -> JointStiffness:
    """One joint's stiffness; omitted keys are rigid (``torsional`` defaults to ``rotational``)."""
    if not isinstance(entry, Mapping):
        raise UserError(f"{where}: a joint entry is a mapping of {', '.join(JOINT_KEYS)}")
    unknown = set(entry) - set(JOINT_KEYS)
    if unknown:
        raise UserError(f"{where}: unknown key(s) {', '.join(sorted(map(str, unknown)))}; use {', '.join(JOINT_KEYS)}")
    values = {key: _number(entry, key, where) for key in JOINT_KEYS if key in entry}
    return JointStiffness(**values)


def joints_from_data(data) -> tuple[JointStiffness, ...]:
    """``joints``: absent (rigid), one mapping for every joint, or a list of five mappings."""
    if data is None:
        return RIGID_JOINTS
    if isinstance(data, Mapping):
        return (joint_from_mapping(data, "joints"),) * len(JOINT_NAMES)
    if not isinstance(data, Sequence) or isinstance(data, str) or len(data) != len(JOINT_NAMES):
        raise UserError(f"'joints' must be one mapping or a list of {len(JOINT_NAMES)} (joints {', '.join(JOINT_NAMES)})")
    return tuple(joint_from_mapping(e, f"joint {k + 1}") for k, e in enumerate(data))


def design_from_mapping(data: Mapping) -> RCubeDesign:
    """A design from a mapping; missing links take the final design's links (Table 7.8)."""
    if not isinstance(data, Mapping):
        raise UserError("a design file holds a mapping of l1, l2, l3, links, ...")
    base = final_design()
    geometry = RCubeGeometry(
        float(data.get("l1", base.geometry.l1)),
        float(data.get("l2", base.geometry.l2)),
        float(data.get("l3", base.geometry.l3)),
        None if data.get("offset") is None else float(data["offset"]),
        int(data.get("sigma", -1)),
    )
    density = float(data.get("density", FINAL_DENSITY))
    joints = joints_from_data(data.get("joints"))
    links = data.get("links")
    if links is None:
        return RCubeDesign(geometry, base.links, joints=joints)
    if not isinstance(links, Sequence) or len(links) != 3:
        raise UserError("'links' must list exactly three link entries")
    return RCubeDesign(geometry, tuple(link_from_mapping(e, density, f"link {k + 1}") for k, e in enumerate(links)),
                       joints=joints)


def load_design(path: Path) -> RCubeDesign:
    """Read a YAML or JSON design file."""
    data = parse_structured(read_text(path, "design file"), "yaml", str(path))  # JSON is YAML too
    return design_from_mapping(data)
