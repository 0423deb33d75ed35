"""vtool: elastic valve-train dynamics with clearances, sonic-boom and condensed-plate checks.

The installed package maps the repository folders into one namespace:
``vtool.app`` (CLI and TUI), ``vtool.presets`` (TOML presets and their loaders),
``vtool.assessments`` (sonic boom, plate condensation) and ``vtool.solvers``
(valve-train model and back ends). Dependencies point one way:
app -> presets -> assessments -> solvers.
"""

__version__ = "0.1.0"
