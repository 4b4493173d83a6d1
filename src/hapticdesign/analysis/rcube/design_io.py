"""R-CUBE designs from command-line values or a YAML/JSON design file.

File keys (SI units): ``l1, l2, l3`` (m), optional ``offset`` (m), ``sigma``, ``density``
(kg/m^3), ``links``: three entries ``{D, d, plies: [a, b, c, d]}`` (plies at 0, 90, -45 and
45 degrees of M55J) or ``{D, d, E, G}`` (isotropic, Pa), and ``joints``: one entry for every joint
or a list of five (joints ``phi_i1 .. phi_i5``, eq. 5.5-5.14), each ``{rotational, translational,
torsional}`` in N m/rad, N/m, N m/rad (any omitted: rigid; ``torsional`` defaults to ``rotational``),
and ``tolerances: {l1, l2, l3, joint_offset}`` (m, the Monte Carlo of manufacturing tolerances).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

from hapticdesign.errors import UserError
from hapticdesign.files import parse_structured, quote, read_text
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.analysis.rcube.design import FINAL_DENSITY, JOINT_NAMES, RIGID_JOINTS, RCubeDesign, final_design
from hapticdesign.analysis.stiffness.joints import JointStiffness
from hapticdesign.analysis.stiffness.link import LinkDesign
from hapticdesign.analysis.stiffness.materials import isotropic, laminate
from hapticdesign.analysis.stiffness.sections import Tube


DESIGN_KEYS = ("l1", "l2", "l3", "offset", "sigma", "density", "links", "joints", "tolerances")
"""Keys of a design file; ``tolerances`` is read by :func:`~.tolerance.tolerances_from_file` (``rcube tolerance``)."""
LINK_KEYS = ("D", "d", "plies", "E", "G", "density")


def _number(entry: Mapping, key: str, where: str, positive: bool = False) -> float:
    if key not in entry:
        raise UserError(f"{where}: missing {key!r}")
    value = entry[key]
    if isinstance(value, bool):
        raise UserError(f"{where}: {key} must be a number, got {quote(value)}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise UserError(f"{where}: {key} must be a number, got {quote(value)}") from None
    if not math.isfinite(number) or (positive and number <= 0):
        raise UserError(f"{where}: {key} must be a {'positive ' if positive else ''}finite number, got {quote(value)}")
    return number


def _known(entry: Mapping, keys: tuple[str, ...], where: str) -> None:
    unknown = sorted(map(str, set(entry) - set(keys)))
    if unknown:
        raise UserError(f"{where}: unknown key(s) {', '.join(quote(k) for k in unknown[:5])}; use {', '.join(keys)}")


def _plies(value, where: str) -> tuple[int, int, int, int]:
    if (not isinstance(value, Sequence) or isinstance(value, str) or len(value) != 4
            or not all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 1000 for v in value)):
        raise UserError(f"{where}: plies must be four whole numbers of plies at 0, 90, -45, 45 degrees, "
                        f"got {quote(value)}")
    return tuple(value)


def link_from_mapping(entry: Mapping, density: float, where: str) -> LinkDesign:
    """One link: a tube plus either ply counts (M55J laminate) or isotropic ``E`` and ``G``."""
    if not isinstance(entry, Mapping):
        raise UserError(f"{where}: a link entry is a mapping of {', '.join(LINK_KEYS)}")
    _known(entry, LINK_KEYS, where)
    tube = Tube(_number(entry, "D", where, True), _number(entry, "d", where, True))
    if "plies" in entry:
        moduli = laminate(_plies(entry["plies"], where))
    elif "E" in entry:
        moduli = isotropic(_number(entry, "E", where), _number(entry, "G", where) if "G" in entry else None)
    else:
        raise UserError(f"{where}: give 'plies' (M55J laminate) or 'E' (isotropic material)")
    return LinkDesign(tube, moduli, _number(entry, "density", where, True) if "density" in entry else density)


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
    _known(data, DESIGN_KEYS, "design file")
    base = final_design()
    lengths = [_number(data, k, "design file", True) if k in data else getattr(base.geometry, k)
               for k in ("l1", "l2", "l3")]
    offset = None if data.get("offset") is None else _number(data, "offset", "design file")
    sigma = data.get("sigma", -1)
    if sigma not in (-1, 1) or isinstance(sigma, bool):
        raise UserError(f"design file: sigma must be -1 or 1 (the passive configuration, eq. 5.42), got {quote(sigma)}")
    geometry = RCubeGeometry(*lengths, offset, int(sigma))
    density = _number(data, "density", "design file", True) if "density" in data else FINAL_DENSITY
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
