"""Condensed-plate checks: plate elements, Irons/Guyan reduction, exact references (thesis 001, part II)."""
