"""R-CUBE design optimization (seed 001 ch. 6-7): kinematic synthesis by NSGA-II, post-evaluation
and selection of a Pareto solution, the weighted-sum particle-swarm route, the hollow cross-section
ratio and the composite ply counts, chained by :mod:`hapticdesign.optimization.chain`."""
