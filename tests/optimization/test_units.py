"""Each design variable's unit, as the study's tables print it (issue 45 item 5: the tables carried no units).

Oracle: the device file's own grammar: a parameter a rotation reads is an angle, one a translation reads a length;
a body's m, r, I fields are kg, m, kg m^2; a motor on a prismatic joint works in N, on a revolute one in N m."""

from __future__ import annotations

from hapticdesign.devices.design_space import DesignSpace

DEVICE = {
    "name": "units",
    "parameters": {"l": 0.2, "tilt": 0.1},
    "joints": [{"name": "q1"}, {"name": "s", "type": "prismatic"}],
    "frames": [{"name": "a", "transforms": [{"Rz": "q1 + tilt"}, {"tx": "l"}]},
               {"name": "b", "parent": "a", "transforms": [{"tx": "s"}]}],
    "bodies": [{"name": "2", "frame": "b", "m": 0.1, "rx": 0.01, "Ixx": 1e-5, "Iyy": 1e-5, "Izz": 1e-5}],
    "end_effector": "b",
    "actuators": [{"joint": "q1", "coulomb": 0.01, "gear_ratio": 10.0}, {"joint": "s", "coulomb": 0.5, "damping": 1.0}],
}


def test_each_variable_has_the_unit_of_what_it_changes():
    names = ["l", "tilt", "m2", "r2x", "Ixx2", "actuators.q1.coulomb", "actuators.s.coulomb", "actuators.s.damping",
             "actuators.q1.gear_ratio", "actuators.s.gear_ratio"]
    space = DesignSpace(DEVICE, names)
    units = [v.unit(space.spec) for v in space.variables]
    assert units == ["m", "rad", "kg", "m", "kg m^2", "N m", "N", "N s/m", "1", "rad/m"]
