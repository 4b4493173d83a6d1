"""Modified R-CUBE analysis (seed 001 ch. 5): kinematics, stiffness, dynamics."""
