"""Performance metrics of haptic devices from any Jacobian, inertia or stiffness matrix (seed 001 ch. 4, §6.1-6.3)."""
