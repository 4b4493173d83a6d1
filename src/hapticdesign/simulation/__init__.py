"""Sampled-data haptic rendering simulation (seed 000 chapter 4).

- :mod:`.tables`: the equations of motion as coefficient tables, evaluated inside numba.
- :mod:`.loop`: the fixed-step plant with the digital side (sampling, quantization, delay,
  zero-order hold, model-based compensator, virtual wall, safety switch, optional hand).
- ``tests/helpers/reference.py`` (outside the package, for the tests and benchmarks): the same loop written
  plainly with ``scipy.integrate.solve_ivp``.
- :mod:`.impedance`: the stable impedance range (seed §4.1.2-4.1.3).
- :mod:`.boundary`: exact and simulated stability boundary of a 1-DOF mass-damper.
- :mod:`.analytic` and :mod:`.analytic_driven`: the impedance range from the exact linear response of
  the sampled loop (type 2 as a linear time-varying loop along the driven motion).
- :mod:`.robustness`: the stable range under modelling error (seeded draws, confidence intervals).
- :mod:`.transparency`: the transparency bandwidth (seed §4.2.2-4.2.3).
- :mod:`.campaign` and :mod:`.figures`: design-set campaigns (seed §4.1.4, §4.2.4).
"""
