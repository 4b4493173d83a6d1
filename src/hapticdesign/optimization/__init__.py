"""Design optimization of any device: study files (:mod:`.study_file`), bound to a device file and evaluated
(:mod:`.study_evaluation`), their methods (:mod:`.study_methods`) and runs (:mod:`.study_run`, NSGA-II through
:mod:`.pymoo_run`; the convex LN program, :mod:`.study_convex`), outputs and front selection (:mod:`.study_outputs`,
:mod:`.front_selection`). The modified
R-CUBE's chain of seed 001 ch. 6-7 (synthesis, selection, cross-section, plies) is its own room,
:mod:`hapticdesign.optimization.rcube`."""
