"""The Linearity Number (seed 000 chapter 3, Appendices B-D).

- :mod:`.form`: LN as an exact quadratic form in the standard inertial parameters (eq. 3.1-3.4);
  ``device_form`` gives a device's.
- :mod:`.region`, :mod:`.weights`: the region R and the entry weights.
- :mod:`.closed_form`: LN as a polynomial in the seed's design variables (Appendix B).
- :mod:`.conditions`: LN = 0 as linear equations; in the seed's variables (eq. 3.12-3.27).
- :mod:`.bounds`, :mod:`.convex`, :mod:`.linear_designs`: realizable fully linear designs (eq. 3.28-3.33).
- :mod:`.design_sets`: designs at prescribed LN levels (§3.2.2, Table 3.3).
- :mod:`.verdict`: the 6-DOF answer with its certificate and the minimum LN (§3.3, Appendix D).
"""
