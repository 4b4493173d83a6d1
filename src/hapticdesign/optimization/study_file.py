"""The study file: what to optimize on a device file (YAML or TOML, docs/optimization.md).

A study names a device file (relative to the study file), the ``variables`` the optimizer may change
(continuous bounds ``[low, high]`` or a discrete choice ``{values: [...]}``), the ``workspace`` the handle
must reach (a box and a grid), the ``objectives`` (an index reduced over the workspace and a sense), the
``constraints`` (an index or an affine expression of the variables, bounded by ``<=`` and/or ``>=``) and
the ``algorithm`` (one record per method, :data:`AlgorithmSettings`: NSGA-II, NSGA-III or particle swarm, population
and generations; or ``convex``, seed 000's exact LN minimization over inertial parameters, which needs no workspace).
Everything is checked here with one-line messages naming the field; the names of variables and indices are
checked against the device and the index registry when the study is bound to them (:mod:`.study_run`).

Expressions use the device files' grammar (:func:`hapticdesign.devices.schema.parse_expression`):
``l1 + l2``, ``2*l1 - d``; their names are variables of the study.
"""

from __future__ import annotations

import functools
import hashlib
import math
from pathlib import Path
from typing import Annotated, ClassVar, Literal, get_args

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError, field_validator, model_validator

from hapticdesign.analysis.metrics.indices import INDICES, check_reduction
from hapticdesign.devices.builder import LinearExpr
from hapticdesign.devices.device_file import describe_validation_error
from hapticdesign.devices.schema import parse_expression
from hapticdesign.errors import UserError
from hapticdesign.files import load_structured, quote, read_text
from hapticdesign.optimization.formula import Formula, formula

SENSES = ("min", "max")
MAX_VARIABLES = 128
MAX_CHOICES = 1000
MAX_GRID = 101


def _finite(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"expected a number, got {quote(value)}")
    if not math.isfinite(value):
        raise ValueError(f"expected a finite number, got {value!r}")
    return float(value)


Finite = Annotated[float, BeforeValidator(_finite)]


class _StudyModel(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


class Choice(_StudyModel):
    """A discrete variable: one of ``values`` (distinct, in the given order)."""

    values: tuple[Finite, ...] = Field(min_length=1, max_length=MAX_CHOICES)

    @model_validator(mode="after")
    def _distinct(self) -> "Choice":
        if len(set(self.values)) != len(self.values):
            raise ValueError("values: each choice must be given once")
        return self


def _variable(value: object) -> object:
    if isinstance(value, (list, tuple)):
        if len(value) != 2:
            raise ValueError(f"bounds are [low, high], got {len(value)} numbers")
        low, high = (_finite(v) for v in value)
        if not low < high:
            raise ValueError(f"bounds need low < high, got [{low:g}, {high:g}] (fix a value in the device file "
                             "instead of giving equal bounds)")
        return (low, high)
    if isinstance(value, dict):
        try:
            return Choice.model_validate(value)
        except ValidationError as exc:
            raise ValueError(describe_validation_error(exc)) from None
    if isinstance(value, Choice):
        return value
    raise ValueError(f"a variable is [low, high] or {{values: [...]}}, got {quote(value)}")


Variable = Annotated[tuple[float, float] | Choice, BeforeValidator(_variable)]


class Box(_StudyModel):
    """An axis-aligned box of the base frame: ``center`` and edge lengths ``size`` (m, >= 0)."""

    center: tuple[Finite, Finite, Finite]
    size: tuple[Finite, Finite, Finite]

    @model_validator(mode="after")
    def _sizes(self) -> "Box":
        if any(s < 0.0 for s in self.size):
            raise ValueError(f"size: edge lengths must be at least 0 m, got {list(self.size)}")
        return self


class WorkspaceSpec(_StudyModel):
    """The region the handle must reach: ``box`` sampled by ``grid`` points per axis of nonzero size
    (edges included); an axis of size 0 contributes its centre."""

    box: Box
    grid: Annotated[int, Field(strict=True, ge=1, le=MAX_GRID)] = 5


def _bounds(data: object) -> object:
    if isinstance(data, dict) and "<=" not in data and ">=" not in data:
        raise ValueError("a constraint needs a bound: '<=' and/or '>='")
    return data


class _Bounded(_StudyModel):
    """A quantity bounded by ``<=`` and/or ``>=``: the one place that reads a bound's side, sign and word."""

    at_most: Finite | None = Field(None, alias="<=")
    at_least: Finite | None = Field(None, alias=">=")

    @property
    def sides(self) -> tuple[tuple[float, float, str], ...]:
        """Each bound given, ``<=`` first, as (bound, sign, word): a value meets it when
        ``sign * (value - bound) <= 0``."""
        both = ((self.at_most, 1.0, "<="), (self.at_least, -1.0, ">="))
        return tuple((bound, sign, word) for bound, sign, word in both if bound is not None)

    def beyond(self, value: float) -> list[tuple[float, float, str]]:
        """Each side of :attr:`sides` as (how far ``value`` is beyond the bound, scaled by the bound's size, 1 for a
        bound of 0; the bound; its word): above 0 where ``value`` misses the bound (NaN for a NaN value)."""
        return [(sign * (value - bound) / (abs(bound) if bound != 0.0 else 1.0), bound, word)
                for bound, sign, word in self.sides]

    @staticmethod
    def missed(label: str, value: float, bound: float, word: str) -> str:
        """A bound missed, in words: ``l1 + l2 = 0.31, not <= 0.3``."""
        return f"{label} = {value:.6g}, not {word} {bound:g}"

    @model_validator(mode="after")
    def _ordered(self) -> "_Bounded":
        if self.at_most is None and self.at_least is None:
            raise ValueError("a bound is needed: '<=' and/or '>=' (without one it removes nothing)")
        if self.at_most is not None and self.at_least is not None and not self.at_least <= self.at_most:
            raise ValueError(f"'>=' {self.at_least:g} is above '<=' {self.at_most:g}: nothing can meet both")
        return self


OptionValue = int | float | list[Finite] | str | None


class _IndexUse(_StudyModel):
    """An index of the registry, its ``options`` (``kmax``'s sample period, delay, damping, direction; see
    docs/indices.md) and its reduction over the workspace points."""

    index: str = Field(min_length=1, max_length=64)
    reduce: str = Field(max_length=64)
    """One of :data:`hapticdesign.analysis.metrics.indices.REDUCTIONS` (``center`` needs an odd grid)."""
    options: dict[str, OptionValue] = Field({}, max_length=16)

    @field_validator("reduce")
    @classmethod
    def _reduction(cls, how: str) -> str:
        try:
            return check_reduction(how)
        except UserError as exc:
            raise ValueError(str(exc)) from None

    @property
    def request(self) -> tuple[str, tuple]:
        """The index with its options, hashable: designs are asked each such request once."""
        return (self.index, tuple(sorted((k, tuple(v) if isinstance(v, list) else v) for k, v in self.options.items())))

    @property
    def key(self) -> tuple:
        """The request and its reduction."""
        return (*self.request, self.reduce)


class IndexConstraint(_Bounded, _IndexUse):
    """An index reduced over the workspace, bounded."""

    @property
    def label(self) -> str:
        """``min_isotropy``; with options, they follow in brackets: ``max_rcube_constraint[point=C2]``."""
        shown = ",".join(f"{k}={v}" for k, v in self.request[1])
        return f"{self.reduce}_{self.index}" + (f"[{shown}]" if shown else "")


@functools.lru_cache(maxsize=256)
def _parsed(text: str) -> LinearExpr:
    """The expression ``text`` parsed once (a study's constraints are read at every design)."""
    return parse_expression(text)


class ExpressionConstraint(_Bounded):
    """An affine expression of the variables (the device files' grammar), bounded."""

    expression: str = Field(min_length=1, max_length=1000)

    @field_validator("expression")
    @classmethod
    def _parses(cls, text: str) -> str:
        parse_expression(text)
        return text

    @property
    def parsed(self) -> LinearExpr:
        return _parsed(self.expression)

    @property
    def label(self) -> str:
        return self.expression

    def value(self, values: dict[str, float]) -> float:
        """The expression at the variables' ``values``."""
        parsed = self.parsed
        return parsed.constant + sum(c * values[name] for name, c in parsed.terms)


def _constraint(value: object) -> object:
    value = _bounds(value)
    if isinstance(value, (IndexConstraint, ExpressionConstraint)):
        return value
    if isinstance(value, dict):
        kind = ExpressionConstraint if "expression" in value else IndexConstraint
        try:
            return kind.model_validate(value)
        except ValidationError as exc:
            raise ValueError(describe_validation_error(exc)) from None
    raise ValueError(f"a constraint is a mapping such as {{index: isotropy, reduce: min, '>=': 0.1}}, got {quote(value)}")


Constraint = Annotated[IndexConstraint | ExpressionConstraint, BeforeValidator(_constraint)]


class Objective(_IndexUse):
    """An index reduced over the workspace, minimized or maximized; ``name`` labels it (default: the index)."""

    name: str = Field("", max_length=64)
    sense: Literal["min", "max"]

    @model_validator(mode="after")
    def _default_name(self) -> "Objective":
        if not self.name:
            object.__setattr__(self, "name", self.index)
        return self


def _formula(value: object) -> Formula:
    if isinstance(value, Formula):
        return value
    try:
        return formula(value)
    except UserError as exc:
        raise ValueError(str(exc)) from None


FormulaText = Annotated[Formula, BeforeValidator(_formula)]


class Keep(_Bounded):
    """A formula of the variables and parameters, bounded: the front keeps the designs that meet it (the search
    does not see it)."""

    formula: FormulaText


class Start(_StudyModel):
    """The design that minimizes ``minimize`` (a formula of the variables and parameters) under the study's
    constraints, found by SciPy's SLSQP from ``starts`` seeded starts and placed in every run's first population."""

    minimize: FormulaText
    starts: Annotated[int, Field(strict=True, ge=1, le=1000)] = 32


POLISH = ("none", "ends", "all")
"""What a population search's front has refined by a local search (:mod:`.study_polish`): nothing, the best design
of each objective (the default), or every front design."""


class _PopulationSearch(_StudyModel):
    """The settings every population search shares: ``population`` designs over ``generations`` generations;
    ``runs``: several runs, each with its own bounds of some continuous variables (run ``k`` seeded ``seed + k``),
    merged; ``front``: the front of every evaluated design (``archive``) or of the runs' final populations
    (``final``); ``start``: a minimized design in the first populations (:class:`Start`); ``polish``: the front
    designs refined by a local search under the study's constraints afterwards (:data:`POLISH`)."""

    population: Annotated[int, Field(strict=True, ge=4, le=100_000)] = 40
    generations: Annotated[int, Field(strict=True, ge=1, le=100_000)] = 60
    runs: list[dict[str, Variable]] = Field([], max_length=100)
    front: Literal["archive", "final"] = "archive"
    start: Start | None = None
    polish: Literal["none", "ends", "all"] = "ends"
    """``ends`` by default: the front's ends are the optima (a population search alone stops near them); ``none``
    keeps the raw search (faster)."""

    over_poses: ClassVar[bool] = True
    """Whether the method evaluates designs at the workspace's poses (a study then needs a workspace)."""
    one_objective: ClassVar[bool] = False
    """Whether the method minimizes a single objective."""

    @property
    def designs(self) -> int:
        """How many designs the search evaluates (polishing aside)."""
        return self.population * self.generations * max(1, len(self.runs))

    @property
    def options(self) -> dict:
        """The method's own settings as pymoo's algorithm takes them (:class:`~.pymoo_run.AlgorithmSpec`)."""
        return {}


class Nsga2(_PopulationSearch):
    """``nsga2``: NSGA-II (Deb et al. 2002, pymoo), constrained domination."""

    method: Literal["nsga2"] = "nsga2"


class Nsga3(_PopulationSearch):
    """``nsga3``: NSGA-III (Deb & Jain 2014, pymoo) for many objectives: survival by the niches of Das-Dennis
    reference directions with ``partitions`` divisions of each objective axis (by default the most whose directions
    fit in the population)."""

    method: Literal["nsga3"]
    partitions: Annotated[int, Field(strict=True, ge=1, le=1000)] | None = None

    @property
    def options(self) -> dict:
        return {"partitions": self.partitions}


class Pso(_PopulationSearch):
    """``pso``: particle swarm optimization (Kennedy & Eberhart 1995, pymoo) of one objective; continuous variables
    only."""

    method: Literal["pso"]

    one_objective: ClassVar[bool] = True


class Convex(_StudyModel):
    """``convex``: the exact convex program of seed 000's LN minimization over inertial parameters
    (:mod:`.study_convex`), each body kept ``realizability``: ``rigid-body`` (pseudo-inertia positive
    semi-definite, Wensing et al. 2017) or ``positive-definite`` (the seed's eq. 3.28)."""

    method: Literal["convex"]
    realizability: Literal["rigid-body", "positive-definite"] = "rigid-body"

    over_poses: ClassVar[bool] = False
    polish: ClassVar[str] = "none"
    """The program's design is the exact minimum: nothing to polish."""

    @property
    def designs(self) -> int:
        return 1


AlgorithmSettings = Annotated[Nsga2 | Nsga3 | Pso | Convex, Field(discriminator="method")]
"""The ``algorithm`` of a study: one record per method, chosen by ``method`` (:func:`algorithm_settings`; each record's
pymoo algorithm and run: :data:`~hapticdesign.optimization.study_methods.METHODS`)."""


def method_name(settings: type[_StudyModel]) -> str:
    """The ``algorithm.method`` of a method's settings record (``nsga2`` of :class:`Nsga2`)."""
    return get_args(settings.model_fields["method"].annotation)[0]


def _settings() -> dict[str, type[_StudyModel]]:
    """Each method's settings record by its name (the members of :data:`AlgorithmSettings`)."""
    return {method_name(record): record for record in get_args(get_args(AlgorithmSettings)[0])}


def algorithm_settings(value: dict) -> Nsga2 | Nsga3 | Pso | Convex:
    """The ``algorithm`` mapping as its method's record (``nsga2`` without ``method``); a setting of another method
    is refused in one line naming the methods it belongs to."""
    settings = _settings()
    method = value.get("method", "nsga2")
    if method not in settings:
        raise ValueError(f"algorithm.method: unknown method {quote(method)}; choose one of {', '.join(settings)}")
    record = settings[method]
    for key in value:
        owners = [name for name, other in settings.items() if key in other.model_fields]
        if key not in record.model_fields and owners:
            named = " and ".join([", ".join(owners[:-1]), owners[-1]] if len(owners) > 1 else owners)
            raise ValueError(f"algorithm.{key}: a setting of method {named}, not of method {method} "
                             f"(its settings: {', '.join(k for k in record.model_fields if k != 'method')})")
    try:
        return record.model_validate({**value, "method": method})
    except ValidationError as exc:
        raise ValueError(f"algorithm.{describe_validation_error(exc)}") from None


class StudySpec(_StudyModel):
    """A whole study file."""

    device: str = Field(min_length=1, max_length=1000)
    variables: dict[str, Variable] = Field(min_length=1, max_length=MAX_VARIABLES)
    workspace: WorkspaceSpec | None = None
    objectives: list[Objective] = Field(min_length=1, max_length=16)
    constraints: list[Constraint] = Field([], max_length=64)
    parameters: dict[str, FormulaText] = Field({}, max_length=MAX_VARIABLES)
    """Device parameters computed from the variables (and the parameters above them) by a formula."""
    keep: list[Keep] = Field([], max_length=16)
    algorithm: AlgorithmSettings = Nsga2()

    @model_validator(mode="before")
    @classmethod
    def _algorithm(cls, data: object) -> object:
        if isinstance(data, dict) and isinstance(data.get("algorithm"), dict):
            return {**data, "algorithm": algorithm_settings(data["algorithm"])}
        return data

    @model_validator(mode="after")
    def _names(self) -> "StudySpec":
        if self.workspace is None and self.algorithm.over_poses and not self.parameters_only:
            raise ValueError("workspace: the region the handle must reach is required (only method convex, whose "
                             "LN is over the joint region, and a study of parameter indices alone do without)")
        centered = [use.index for use in self.index_uses if use.reduce == "center"]
        if centered and self.workspace is None:
            raise ValueError(f"workspace: reduce center ({centered[0]}) needs a workspace, whose box's centre it reads")
        if centered and self.workspace.grid % 2 == 0 and any(self.workspace.box.size):
            raise ValueError(f"workspace.grid: reduce center ({centered[0]}) needs the box's centre among the grid "
                             f"points, an odd grid; got {self.workspace.grid}")
        if isinstance(self.algorithm, _PopulationSearch) and self.algorithm.one_objective and len(self.objectives) > 1:
            raise ValueError(f"objectives: method {self.algorithm.method} minimizes one objective, not "
                             f"{len(self.objectives)} (use method nsga2 or nsga3)")
        names = [o.name for o in self.objectives]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"objectives: name {twice[0]!r} is used twice (give each objective its own name)")
        clash = [n for n in names if n in self.variables]
        if clash:
            raise ValueError(f"objectives: name {clash[0]!r} is also a variable (name the objective otherwise)")
        for i, c in enumerate(self.constraints):
            if isinstance(c, ExpressionConstraint):
                unknown = [n for n in c.parsed.names if n not in self.variables]
                if unknown:
                    raise ValueError(f"constraints[{i}]: {unknown[0]!r} in {c.expression!r} is not a variable of the study "
                                     f"(variables: {', '.join(self.variables)})")
        known = list(self.variables)
        for name, f in self.parameters.items():
            if name in self.variables:
                raise ValueError(f"parameters: {name!r} is a variable; a parameter is computed from the variables")
            self._names_known(f"parameters.{name}", f, known)
            known.append(name)
        search = self.algorithm if isinstance(self.algorithm, _PopulationSearch) else _PopulationSearch()
        for where, f in [*((f"keep[{i}]", k.formula) for i, k in enumerate(self.keep)),
                         *((("algorithm.start", search.start.minimize),) if search.start else ())]:
            self._names_known(where, f, known)
        for k, run in enumerate(search.runs):
            for name, bounds in run.items():
                if name not in self.variables or isinstance(self.variables[name], Choice) or isinstance(bounds, Choice):
                    raise ValueError(f"algorithm.runs[{k}]: {name!r} is not a continuous variable of the study")
        return self

    @staticmethod
    def _names_known(where: str, f: Formula, known: list[str]) -> None:
        unknown = [n for n in f.names if n not in known]
        if unknown:
            raise ValueError(f"{where}: {unknown[0]!r} in {f.text!r} is not a variable or parameter above it")

    @property
    def formula_variables(self) -> tuple[str, ...]:
        """The variables the ``parameters`` formulas read."""
        used = {n for f in self.parameters.values() for n in f.names}
        return tuple(v for v in self.variables if v in used)

    def with_parameters(self, values: dict[str, float]) -> dict[str, float]:
        """The variables' ``values`` and the ``parameters`` computed from them, in order."""
        out = dict(values)
        for name, f in self.parameters.items():
            out[name] = f.value(out)
        return out

    @property
    def parameters_only(self) -> bool:
        """True when every index the study reads is registered and an index of the parameters alone (a closed form
        of the device's parameters, such as the R-CUBE's): no pose is reached, the study needs no workspace."""
        return all(use.index in INDICES and INDICES[use.index].of_parameters for use in self.index_uses)

    @property
    def index_uses(self) -> tuple[_IndexUse, ...]:
        """The objectives and the index constraints: every index the study reads."""
        return (*self.objectives, *(c for c in self.constraints if isinstance(c, IndexConstraint)))


class Study:
    """A checked study file bound to its device file: ``spec``, the study file's ``path``, the device path
    (resolved against the study file's folder), both files' text and a ``fingerprint`` of the two (a
    checkpoint is resumed only by the same study)."""

    def __init__(self, spec: StudySpec, path: Path, device_path: Path, study_text: str, device_text: str):
        self.spec = spec
        self.path = path
        self.device_path = device_path
        self.study_text = study_text
        self.device_text = device_text

    @property
    def fingerprint(self) -> str:
        digest = hashlib.sha256()
        for text in (self.study_text, self.device_text):
            digest.update(text.encode())
            digest.update(b"\0")
        return digest.hexdigest()


def study_from_mapping(data: object, source: str = "study file") -> StudySpec:
    """Validate a parsed study file; problems raise a one-line UserError naming the field."""
    if not isinstance(data, dict):
        raise UserError(f"{source}: expected a mapping with keys device, variables, workspace, objectives")
    try:
        return StudySpec.model_validate(data)
    except ValidationError as exc:
        raise UserError(f"{source}: {describe_validation_error(exc)}") from None


def load_study(path: Path | str) -> Study:
    """Read a study file (``.yaml``, ``.yml``, ``.toml`` or ``.json``) and its device file."""
    path = Path(path)
    spec = study_from_mapping(load_structured(path, "study file"), str(path))
    device_path = path.parent / spec.device
    return Study(spec, path, device_path, read_text(path, "study file"), read_text(device_path, "device file"))
