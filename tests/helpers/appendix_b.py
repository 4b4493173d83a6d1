"""Seed 000 Appendix B.1 as printed, transcribed once for the LN tests."""


def appendix_b1_gravity(p, l2, l3a, g):
    """The gravity polynomial printed at the end of seed 000 Appendix B.1."""
    return 0.5 * g**2 * (
        l2**2 * p["m2a"] ** 2 + 2 * l3a**2 * p["m2a"] ** 2 + 2 * l2**2 * p["m2a"] * p["m3"] + l2**2 * p["m3"] ** 2
        + 4 * l3a**2 * p["m2a"] * p["m3a"] + 2 * l3a**2 * p["m3a"] ** 2 + 2 * l2 * p["m2a"] ** 2 * p["r2ax"]
        + 2 * l2 * p["m2a"] * p["m3"] * p["r2ax"] + p["m2a"] ** 2 * p["r2ax"] ** 2 + p["m2a"] ** 2 * p["r2ay"] ** 2
        + 2 * l2 * p["m2"] * p["m2a"] * p["r2x"] + 2 * l2 * p["m2"] * p["m3"] * p["r2x"]
        + 2 * p["m2"] * p["m2a"] * p["r2ax"] * p["r2x"] + p["m2"] ** 2 * p["r2x"] ** 2
        + 2 * p["m2"] * p["m2a"] * p["r2ay"] * p["r2y"] + p["m2"] ** 2 * p["r2y"] ** 2 + 2 * p["m3a"] ** 2 * p["r3ax"] ** 2
        + 4 * l3a * p["m2a"] * p["m3a"] * p["r3az"] + 4 * l3a * p["m3a"] ** 2 * p["r3az"] + 2 * p["m3a"] ** 2 * p["r3az"] ** 2
        + 4 * p["m3"] * p["m3a"] * p["r3ax"] * p["r3x"] + 2 * p["m3"] ** 2 * p["r3x"] ** 2
        + 4 * l3a * p["m2a"] * p["m3"] * p["r3z"] + 4 * l3a * p["m3"] * p["m3a"] * p["r3z"]
        + 4 * p["m3"] * p["m3a"] * p["r3az"] * p["r3z"] + 2 * p["m3"] ** 2 * p["r3z"] ** 2
    )
