"""Closed kinematic loops: the passive-joint solver every analysis consumes (:mod:`.solver`)."""
