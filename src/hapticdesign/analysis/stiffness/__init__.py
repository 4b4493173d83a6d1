"""Virtual-joint-method stiffness with isotropic and composite tube links (seed 001 §4.2, §5.2)."""
