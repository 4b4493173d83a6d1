"""The modified R-CUBE's optimization chain (seed 001 ch. 6-7): kinematic synthesis, selection, cross-section,
plies, and its synthesis indices for study files. It uses the generic study engine of
:mod:`hapticdesign.optimization`; nothing generic imports it."""
