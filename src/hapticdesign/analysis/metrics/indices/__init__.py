"""Design indices of any device: one :class:`Index` type, one registry (:data:`INDICES`), one way to evaluate them
(issues 23, 36; docs/indices.md).

- :mod:`.states`: the design states an index is a function of (a device at poses, many designs' batched poses, the
  parameters alone);
- :mod:`.registry`: :class:`Index`, :class:`Registry`, :data:`INDICES`, the :func:`index` decorator and the
  entry-point group of installed packages' indices;
- :mod:`.builtin`: the built-in indices (``isotropy``, ``apparent_mass``, ``force``, ``kmax``, ``ln``, ...);
- :mod:`.evaluation`: :func:`evaluate` (one design at workspace points), :func:`evaluate_designs` (many, through the
  compiled kernels where they serve), :func:`evaluate_parameters`, :func:`reduce` (and where it is taken,
  :func:`reduced_at`; every reduction at once, :func:`spread`).
"""

from hapticdesign.analysis.metrics.indices import builtin  # noqa: F401  (registers the built-in indices)
from hapticdesign.analysis.metrics.indices.evaluation import (
    REDUCTIONS, Evaluation, check_reduction, evaluate, evaluate_at, evaluate_designs,
    evaluate_parameters, reduce, reduced_at, reduction_label, spread,
)
from hapticdesign.analysis.metrics.indices.registry import (
    INDICES, Index, Registry, Request, compliance_line, drive_compliance, index, options_line, options_used, register,
    requests_of,
)
from hapticdesign.analysis.metrics.indices.states import HandleStates, ParameterStates, handle_jacobians, moving_mass

__all__ = ["INDICES", "REDUCTIONS", "Evaluation", "HandleStates", "Index", "ParameterStates",
           "Registry", "Request", "check_reduction", "compliance_line", "drive_compliance", "evaluate", "evaluate_at", "evaluate_designs",
           "evaluate_parameters", "handle_jacobians", "index", "moving_mass", "options_line", "options_used",
           "reduce", "reduced_at", "reduction_label", "register", "requests_of", "spread"]
