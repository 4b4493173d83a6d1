"""Re-export of :func:`hapticdesign.analysis.kinematics.poses_and_jacobians` for :mod:`.dynamics`."""

from hapticdesign.analysis.kinematics import poses_and_jacobians  # noqa: F401
