"""The one registry of design indices: :class:`Index`, :class:`Registry`, :data:`INDICES` and the :func:`index`
decorator that registers one (docs/indices.md).

An index is one function over a design state (:mod:`.states`): ``function(state, **options)`` gives one value per
pose (or per design, for an index of the parameters alone). It declares its unit, formula, source, its options (the
function's keyword parameters and their defaults) and what it ``needs`` of the state: ``kinematics``, ``dynamics``,
``damping``, ``sections``, ``motors``, ``bodies``, ``gravity``, ``compliance`` (the drive between the motors and the
handle; a device at poses, and the batch of many designs, give them, :data:`~.states.BATCH_NEEDS`), ``device`` (a
device at poses only), or ``parameters`` alone. The built-in indices (:mod:`.builtin`), a device family's own (the
R-CUBE's) and a user's all register the same way, with :func:`index` or :func:`register`.

Indices of installed packages are found through the entry-point group :data:`ENTRY_POINTS` (``[project.entry-points.
"hapticdesign.indices"] name = "package.module"``): the first lookup of a name the registry does not hold imports
every such module once, whose :func:`index` calls register its indices. A study file names indices; it never runs
code.
"""

from __future__ import annotations

import importlib.metadata
import inspect
import re
from collections.abc import Callable, Iterable, Iterator, Mapping
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from hapticdesign.analysis.metrics.indices.states import PARAMETER_NEEDS, POSE_NEEDS
from hapticdesign.analysis.stiffness.drive import compliances
from hapticdesign.errors import RenamedWarning, UserError
from hapticdesign.workload import require_within

ENTRY_POINTS = "hapticdesign.indices"
"""The entry-point group of the packages that register indices."""
NEEDS = POSE_NEEDS | PARAMETER_NEEDS
"""What an index may need of its state (:mod:`.states`)."""
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")
OVER = ("poses", "points")
"""What one value of an index is of (:attr:`Index.over`): a pose, or all of a design's points."""


@dataclass(frozen=True)
class Index:
    """A design index (see the module): ``function(state, **options)`` and what describes it."""

    name: str
    unit: str
    formula: str
    source: str
    function: Callable[..., np.ndarray]
    options: Mapping[str, object] = field(default_factory=dict)
    needs: frozenset[str] = frozenset({"kinematics"})
    cost: float = 1.0
    """How many ordinary evaluations (a pose's kinematics and dynamics) one evaluation of it costs: a study's
    workload counts it so (an index that runs the sampled loop costs about a thousand)."""
    over: str = "poses"
    """``poses``: one value per pose (P,); ``points``: one value per design (D,) from all of its points at once
    (``state.designs`` designs, their poses one after the other), taken at each of its points."""
    renamed: Mapping[str, str] = field(default_factory=dict)
    """Former option names -> their current ones, each taken for one release with a deprecation line
    (:meth:`current`)."""

    def current(self, options: Mapping[str, object]) -> dict[str, object]:
        """``options`` under their current names: a former name (:attr:`renamed`) is taken with a
        :class:`~hapticdesign.errors.RenamedWarning`; the two names of one option at once are a one-line error."""
        out = dict(options)
        for old, new in self.renamed.items():
            if old in out:
                warnings.warn(f"index {self.name}: the option {old!r} is now called {new!r}; {old!r} will be removed",
                              RenamedWarning, stacklevel=3)
                if new in out:
                    raise UserError(f"index {self.name}: give {new} once ({old} is its former name)")
                out[new] = out.pop(old)
        return out

    def values(self, state, options: Mapping[str, object] | None = None) -> np.ndarray:
        """The index of ``state`` with ``options`` over its defaults, as floats, one per pose of ``state`` (one per
        design for an index of the parameters). A function that raises, or answers another shape or a value that
        is not a number, is a one-line UserError naming the index."""
        try:
            found = np.asarray(self.function(state, **{**self.options, **self.current(options or {})}), dtype=float)
        except UserError:
            raise
        except Exception as exc:  # the index's own code (a user's): one line naming it, not a traceback
            raise UserError(f"index {self.name} ({self.source}) failed: {type(exc).__name__}: {exc}") from None
        designs = state.designs if self.over == "points" else None
        wanted = state.count if designs is None else designs
        if found.shape != (wanted,):
            what = "one value per design" if designs is not None or self.of_parameters else "one value per pose"
            raise UserError(f"index {self.name} ({self.source}) returned shape {found.shape}, not ({wanted},): "
                            f"{what}")
        return found if designs is None else np.repeat(found, state.count // designs)

    def __call__(self, state, **options) -> np.ndarray:
        return self.values(state, options)

    @property
    def of_parameters(self) -> bool:
        """True for an index of the parameters alone (no pose is reached)."""
        return self.needs == PARAMETER_NEEDS


@dataclass(frozen=True)
class Request:
    """An index asked for, with options (``kmax``'s sample period, ...); its values are keyed by ``key``."""

    index: str
    options: Mapping[str, object] = field(default_factory=dict)
    label: str | None = None

    @property
    def key(self) -> str:
        return self.label or self.index


class Registry(Mapping[str, Index]):
    """Index name -> :class:`Index`. :data:`INDICES` is the one registry; :meth:`with_indices` gives a view with a
    study's own indices beside it. Looking up a name it does not hold loads the :data:`ENTRY_POINTS` plugins once."""

    def __init__(self, parent: "Registry | None" = None):
        self._own: dict[str, Index] = {}
        self._parent = parent
        self._discovered = parent is not None

    def register(self, index: Index) -> Index:
        """Add ``index``; a name registered already is refused, unless by the same function (a module imported again,
        a notebook cell run again), which replaces it."""
        if not isinstance(index, Index):
            raise UserError(f"an index is made by hapticdesign.index or Index(...), got {type(index).__name__}")
        held = self._find(index.name, discover=False)
        if held is not None and held is not index and _origin(held.function) != _origin(index.function):
            raise UserError(f"index {index.name!r} is registered already (by {held.source}); give yours another name")
        self._own[index.name] = index
        return index

    def with_indices(self, indices: Iterable[Index]) -> "Registry":
        """This registry with ``indices`` beside it (each by its name; this one is left as it is)."""
        out = Registry(self)
        for one in indices:
            out.register(one)
        return out

    def _find(self, name: str, discover: bool = True) -> Index | None:
        found = self._own.get(name)
        if found is None and self._parent is not None:
            found = self._parent._find(name, discover)
        if found is None and discover and not self._discovered:
            self._discover()
            found = self._own.get(name)
        return found

    def _discover(self) -> None:
        """Import every module of the :data:`ENTRY_POINTS` group (each registers its indices)."""
        self._discovered = True
        for point in importlib.metadata.entry_points(group=ENTRY_POINTS):
            try:
                point.load()
            except Exception as exc:  # an installed package's failure, reported as one line naming it
                raise UserError(f"the indices of {point.name!r} ({point.value}) failed to load: "
                                f"{type(exc).__name__}: {exc}") from None

    def __getitem__(self, name: str) -> Index:
        found = self._find(name) if isinstance(name, str) else None
        if found is None:
            raise KeyError(name)
        return found

    def __iter__(self) -> Iterator[str]:
        if not self._discovered:
            self._discover()
        names = dict.fromkeys(self._parent if self._parent is not None else ())
        names.update(dict.fromkeys(self._own))
        return iter(names)

    def __len__(self) -> int:
        return sum(1 for _ in self)


def _origin(function: Callable) -> tuple[str, str]:
    return (getattr(function, "__module__", ""), getattr(function, "__qualname__", repr(function)))


INDICES = Registry()
"""The one registry of design indices (built-ins, plugins, a user's own)."""


def index(function: Callable | None = None, *, unit: str, formula: str | None = None, source: str | None = None,
          name: str | None = None, needs: Iterable[str] = ("kinematics", "dynamics"), cost: float = 1.0,
          over: str = "poses", renamed: Mapping[str, str] | None = None, registry: Registry = INDICES):
    """Register ``function(state, **options)`` as an index (a decorator; the :class:`Index` it returns is callable
    like the function). Its name is the function's (or ``name``), its options its keyword parameters with their
    defaults; ``formula`` defaults to the first line of its docstring, ``source`` to where it is defined. A pose
    index reads ``state.J_v`` (P, 3, n_a), ``state.H`` (P, n_a, n_a), ``state.q`` (P, n_a), ... (every field with
    the leading axis of the P poses, docs/indices.md) and returns (P,) values; with ``over="points"`` it returns one
    value per design, (``state.designs``,), from all of each design's points (the poses are the designs' one after
    the other); an index that ``needs`` ``parameters`` reads ``state.params`` (name -> (D,) values) and returns
    (D,). ``renamed`` maps an option's former names to its current one (taken for one release,
    :meth:`Index.current`)."""

    def make(f: Callable) -> Index:
        label = name or getattr(f, "__name__", "")
        if not NAME.fullmatch(label):
            raise UserError(f"an index name is a Python identifier of at most 64 characters, got {label!r}")
        wanted = frozenset(needs)
        if not wanted or not wanted <= NEEDS or ("parameters" in wanted and len(wanted) > 1):
            raise UserError(f"index {label}: needs is some of {', '.join(sorted(POSE_NEEDS))}, or parameters alone; "
                            f"got {sorted(wanted)}")
        if not isinstance(unit, str) or not unit:
            raise UserError(f"index {label}: unit is a text such as '1', 'kg' or 'N/m'")
        doc = (inspect.getdoc(f) or "").strip().splitlines()
        if not (isinstance(cost, (int, float)) and not isinstance(cost, bool) and 1.0 <= cost < float("inf")):
            raise UserError(f"index {label}: cost is a number of ordinary evaluations, at least 1, got {cost!r}")
        if over not in OVER or (over == "points" and "parameters" in wanted):
            raise UserError(f"index {label}: over is poses (one value per pose) or points (one value per design "
                            f"from all its points; not with needs parameters), got {over!r}")
        made = Index(label, unit, formula or (doc[0] if doc else label), source or ".".join(_origin(f)), f,
                     _options(f, label), wanted, float(cost), over, dict(renamed or {}))
        return registry.register(made)

    return make if function is None else make(function)


def register(made: Index, registry: Registry = INDICES) -> Index:
    """Add an :class:`Index` made otherwise to ``registry`` (see :meth:`Registry.register`)."""
    return registry.register(made)


def _options(function: Callable, label: str) -> dict[str, object]:
    """The keyword parameters after the state, each with its default: the index's options."""
    parameters = list(inspect.signature(function).parameters.values())
    if not parameters or parameters[0].kind not in (inspect.Parameter.POSITIONAL_ONLY,
                                                     inspect.Parameter.POSITIONAL_OR_KEYWORD):
        raise UserError(f"index {label}: the function takes the design state as its first argument")
    options = {}
    for p in parameters[1:]:
        if p.default is inspect.Parameter.empty or p.kind in (inspect.Parameter.VAR_POSITIONAL,
                                                              inspect.Parameter.VAR_KEYWORD):
            raise UserError(f"index {label}: an option is a keyword parameter with a default, {p.name!r} is not")
        options[p.name] = p.default
    return options


def requests_of(requests: Iterable[str | Request], registry: Mapping[str, Index] = INDICES) -> list[Request]:
    """The requests (index names or :class:`Request`), each of a registered index with known options; an unknown
    index or option raises a one-line UserError."""
    out = []
    for request in requests:
        request = Request(request) if isinstance(request, str) else request
        if request.index not in registry:
            raise UserError(f"unknown index {request.index!r} (indices: {', '.join(registry)})")
        request = replace(request, options=registry[request.index].current(request.options))
        known = registry[request.index].options
        unknown = [k for k in request.options if k not in known]
        if unknown:
            raise UserError(f"index {request.index}: unknown option {unknown[0]!r} (options: "
                            f"{', '.join(known) or 'none'})")
        out.append(request)
    keys = [r.key for r in out]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise UserError(f"index {twice[0]} is asked twice (give each request its own label)")
    return out


def options_used(requests: Iterable[Request], registry: Mapping[str, Index] = INDICES) -> dict[str, dict]:
    """The options each checked request ran with (its own over its index's defaults), by request key, for the
    requests whose index has options: what an output states beside the values (``kmax``: the loop settings)."""
    return {r.key: {**registry[r.index].options, **r.options} for r in requests if registry[r.index].options}


def options_line(options: Mapping[str, object]) -> str:
    """``name=value, ...`` of :func:`options_used`'s options of one request, for a text output."""
    return ", ".join(f"{k}={v}" for k, v in options.items())


def drive_compliance(device, indices: Iterable[str], registry: Mapping[str, Index] = INDICES) -> dict[str, str]:
    """Which compliance between the motors and the handle each of the named ``indices`` that include it (``compliance``
    in their needs: ``kmax``) took for ``device``, by index name, each once:
    :func:`~hapticdesign.analysis.stiffness.drive.compliances` (``rigid``, ``transmissions``, ``links`` or
    ``transmissions and links``; the device file's fields decide it). What every output that reports such an index
    states beside its values (:func:`compliance_line` in words); empty when none of them includes it."""
    names = [name for name in dict.fromkeys(indices) if name in registry and "compliance" in registry[name].needs]
    return dict.fromkeys(names, compliances(device)) if names else {}


def compliance_line(compliance: Mapping[str, str]) -> str:
    """:func:`drive_compliance`'s answer in words, ``kmax: drive compliance: links`` (``; `` between indices), empty
    when it is."""
    return "; ".join(f"{name}: drive compliance: {which}" for name, which in compliance.items())


EVALUATION_LIMIT = 1e5
"""Most ordinary index evaluations (a pose's kinematics and dynamics) one run asks for without ``--force``: a study's
designs x points, a map's points, each counted as its costliest index (:attr:`Index.cost`; docs/limits.md)."""


def require_evaluations(what: str, count: float, indices: Iterable[str], registry: Mapping[str, Index] = INDICES) -> None:
    """Refuse ``count`` evaluations (design-points or points) of the named ``indices`` (unknown names cost 1) when,
    each counted as the costliest index's :attr:`Index.cost`, they are above :data:`EVALUATION_LIMIT`."""
    known = [name for name in indices if name in registry]
    costliest = max(known, key=lambda name: registry[name].cost, default=None)
    cost = 1.0 if costliest is None else registry[costliest].cost
    each = "" if cost == 1.0 else f", each costing {cost:g} evaluations (index {costliest})"
    require_within(f"{what}{each}", count * cost, EVALUATION_LIMIT, "design-point evaluations")

