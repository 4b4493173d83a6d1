"""The study file: what it accepts (the issue's example, YAML and TOML) and the one-line errors it gives."""

from __future__ import annotations

import math

import pytest
import yaml

from hapticdesign.errors import UserError
from hapticdesign.optimization.study_file import Choice, ExpressionConstraint, load_study, study_from_mapping

ISSUE_EXAMPLE = """
device: five-bar.yaml
variables:
  l1: [0.06, 0.16]
  m2: [0.01, 0.3]
  links.prox1.D: [0.008, 0.02]
  actuators.q1.gear_ratio: {values: [5, 8, 11.2, 13.3]}
workspace:
  box: {center: [0.0, 0.14, 0.0], size: [0.06, 0.06, 0.0]}
  grid: 5
objectives:
  - {name: isotropy, index: isotropy, reduce: min, sense: max}
  - {name: mass, index: apparent_mass, reduce: max, sense: min}
constraints:
  - {index: isotropy, reduce: min, ">=": 0.1}
  - {expression: "l1 + l2", "<=": 0.35}
algorithm: {method: nsga2, population: 40, generations: 60}
"""


def example() -> dict:
    data = yaml.safe_load(ISSUE_EXAMPLE)
    data["variables"]["l2"] = [0.1, 0.2]
    return data


def test_the_issue_example_reads_with_its_kinds_of_variables_and_constraints():
    spec = study_from_mapping(example())
    assert spec.variables["l1"] == (0.06, 0.16)
    assert spec.variables["actuators.q1.gear_ratio"] == Choice(values=(5.0, 8.0, 11.2, 13.3))
    expression = spec.constraints[1]
    assert isinstance(expression, ExpressionConstraint)
    assert expression.value({"l1": 0.1, "l2": 0.2}) == pytest.approx(0.3)
    assert [use.index for use in spec.index_uses] == ["isotropy", "apparent_mass", "isotropy"]
    assert (spec.algorithm.population, spec.algorithm.generations) == (40, 60)


def test_toml_and_the_device_path_relative_to_the_study_file(tmp_path):
    (tmp_path / "studies").mkdir()
    (tmp_path / "dev.yaml").write_text("name: x\n")
    (tmp_path / "studies" / "s.toml").write_text("""
device = "../dev.yaml"
[variables]
l1 = [0.1, 0.2]
[workspace]
box = {center = [0.0, 0.0, 0.1], size = [0.0, 0.0, 0.0]}
[[objectives]]
index = "isotropy"
reduce = "mean"
sense = "max"
""")
    study = load_study(tmp_path / "studies" / "s.toml")
    assert study.device_path.resolve() == (tmp_path / "dev.yaml").resolve()
    assert study.spec.objectives[0].name == "isotropy"


@pytest.mark.parametrize("change, message", [
    (lambda d: d["variables"].update(l1=[0.2, 0.1]), "variables.l1: bounds need low < high"),
    (lambda d: d["variables"].update(l1=[0.1, 0.1]), "variables.l1: bounds need low < high"),
    (lambda d: d["variables"].update(l1=[math.nan, 0.1]), "variables.l1: expected a finite number"),
    (lambda d: d["variables"].update(l1=[0.1, math.inf]), "variables.l1: expected a finite number"),
    (lambda d: d["variables"].update(l1={"values": []}), "variables.l1: values"),
    (lambda d: d["variables"].update(l1={"values": [1, 1]}), "each choice must be given once"),
    (lambda d: d["variables"].update(l1={"choices": [1, 2]}), "variables.l1: values: missing"),
    (lambda d: d.update(extra=1), "extra: unknown key"),
    (lambda d: d["objectives"][0].update(reduce="worst"), "objectives[0].reduce"),
    (lambda d: d["objectives"][0].update(sense="up"), "objectives[0].sense"),
    (lambda d: d["objectives"][1].update(name="isotropy"), "name 'isotropy' is used twice"),
    (lambda d: d["objectives"][1].update(name="l1"), "'l1' is also a variable"),
    (lambda d: d["constraints"].append({"index": "isotropy", "reduce": "min"}), "needs a bound"),
    (lambda d: d["constraints"].append({"index": "isotropy", "reduce": "min", "<=": 0.1, ">=": 0.2}),
     "nothing can meet both"),
    (lambda d: d["constraints"].append({"expression": "l1 * l2", "<=": 1}), "not an affine expression"),
    (lambda d: d["constraints"].append({"expression": "l1 + l3", "<=": 1}), "'l3' in 'l1 + l3' is not a variable"),
    (lambda d: d["algorithm"].update(method="simplex"), "algorithm.method"),
    (lambda d: d["algorithm"].update(population=1), "algorithm.population"),
    (lambda d: d["workspace"]["box"].update(size=[-0.1, 0, 0]), "edge lengths must be at least 0"),
])
def test_bad_study_files_are_one_line_errors_naming_the_field(change, message):
    data = example()
    change(data)
    with pytest.raises(UserError, match="^study file: ") as caught:
        study_from_mapping(data)
    assert message in str(caught.value) and "\n" not in str(caught.value)
