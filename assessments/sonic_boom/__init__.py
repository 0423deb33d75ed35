"""Sonic-boom assessment of walls and floors (thesis 001, part I)."""
