"""Generated values shared by the CLI property tests (tests/cli/test_*_fuzz.py)."""

from hypothesis import strategies as st

#: text that is a number to some reader and not to others
ODD = ["", " ", "nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e309", "-1e309", "1e-400", "-0", "0", "0.0",
       "4k7", "2u2", "10f", "100f", "3.5MEG", "3.5meg", "1.6 kOhm", "10 kΩ", "0x10", "1_000", "１２", "١٢", "1,5",
       "1.5.5", "--1", "e5", "k", "\t", "1e", "+5", "∞", "None", "[]", "1/2", "1 000", "5%", "1e-300", "1e300",
       "-1", "9" * 400, "1" + "0" * 330, "0." + "0" * 330 + "1"]


def sci():
    """Numbers written as text across 600 orders of magnitude, either sign."""
    return st.builds(lambda sign, m, e: f"{sign}{m:.4g}e{e}", st.sampled_from(["", "", "-"]),
                     st.floats(1.0, 9.999), st.integers(-300, 300))
