"""The deformed mechanism against cam angle, frame by frame over a trace's rows.

Members are drawn from their element shape functions by
:func:`vtool.solvers.model.shapes.deformed_members` (displacements times a scale,
as the thesis' graphics display did); the frame limits are fixed over the
whole run at the current scale so the picture does not jump.

The frame is fitted to the members that carry the motion: a member given
by its ``stiffness`` (the valve spring, whose drawn length is its wire
length, 36 in in Gnilka's presets, kept for its mass) is drawn but left out
of the fit, so it enters the frame from its edge instead of shrinking the
rocker and valve to a few cells.

A run plays in :data:`PLAY_SECONDS` at speed x1 whatever its number of
rows; ``]`` / ``[`` double / halve the speed.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from rich.text import Text
from textual.binding import Binding
from textual.reactive import reactive
from textual.timer import Timer
from textual.widgets import Static

FPS = 10
PLAY_SECONDS = 10.0  # one run at speed x1


class MechanismAnimation(Static, can_focus=True):
    """Play / pause / step through the rows of a valve-train trace."""

    BINDINGS = [
        Binding("space", "play", "Play/pause"),
        Binding("right", "step(1)", "Step"),
        Binding("left", "step(-1)", "Back", show=False),
        Binding("plus,equals_sign", "scale(2)", "Scale+"),
        Binding("minus", "scale(0.5)", "Scale-", show=False),
        Binding("right_square_bracket", "speed(2)", "Faster"),
        Binding("left_square_bracket", "speed(0.5)", "Slower", show=False),
        Binding("home", "first", "First", show=False),
    ]

    DEFAULT_CSS = """
    MechanismAnimation { width: 1fr; height: 1fr; }
    MechanismAnimation:focus { background: $boost; }
    """

    row: reactive[int] = reactive(0, init=False)
    scale: reactive[float] = reactive(1.0, init=False)

    def __init__(self, *, id: str | None = None, color: bool = True) -> None:
        super().__init__("run a simulation (ctrl+r) to animate the mechanism", id=id, markup=False)
        self.trace: Any = None
        self.color = color
        self.playing = False
        self.speed = 1.0
        self._phase = 0.0  # fractional rows carried between ticks
        self.frame_text = ""
        self._timer: Timer | None = None
        self._limits: tuple[tuple[float, float], tuple[float, float]] | None = None

    def show_trace(self, trace: Any) -> None:
        self.pause()
        self.trace = trace
        self._limits = None
        self.set_reactive(MechanismAnimation.row, 0)
        self.draw()

    def clear(self) -> None:
        self.pause()
        self.trace = None
        self.frame_text = ""
        self.update("run a simulation (ctrl+r) to animate the mechanism")

    # ----- frames -----
    @property
    def rows(self) -> int:
        return 0 if self.trace is None else len(self.trace.time)

    def elastic_q(self, row: int) -> np.ndarray:
        n = self.trace.spec.n_coordinates
        return self.trace.q[row, :n]

    def shapes(self, row: int) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        from vtool.solvers.model.shapes import deformed_members

        return deformed_members(self.trace.spec, self.elastic_q(row), self.scale)

    def fitted_members(self) -> set[str]:
        """The members the frame is fitted to: all but those given by a spring rate."""
        members = self.trace.spec.members
        fitted = {m.name for m in members if getattr(m, "stiffness", None) is None}
        return fitted or {m.name for m in members}

    def limits(self) -> tuple[tuple[float, float], tuple[float, float]]:
        if self._limits is None:
            xs, ys = [], []
            fitted = self.fitted_members()
            for row in range(0, self.rows, max(1, self.rows // 60)):
                for name, (x, y) in self.shapes(row).items():
                    if name in fitted:
                        xs.append(x)
                        ys.append(y)
            x_all = np.concatenate(xs) if xs else np.zeros(1)
            y_all = np.concatenate(ys) if ys else np.zeros(1)
            pad_x = 0.1 * max(float(np.ptp(x_all)), 1e-9)
            pad_y = 0.05 * max(float(np.ptp(y_all)), 1e-9)
            # the legend sits in the top left corner: leave it room
            self._limits = ((float(x_all.min()) - 4.0 * pad_x, float(x_all.max()) + pad_x),
                            (float(y_all.min()) - pad_y, float(y_all.max()) + pad_y))
        return self._limits

    def draw(self) -> None:
        if self.trace is None or self.rows == 0:
            return
        width, height = self.size.width, self.size.height
        if width <= 0 or height <= 0:
            return  # hidden: drawn on the resize that shows it
        from vtool.app.plots import shape_chart

        row = min(self.row, self.rows - 1)
        spec = self.trace.spec
        xlim, ylim = self.limits()
        state = "playing" if self.playing else "paused"
        title = (f"cam {self.trace.cam_angle[row]:.1f} deg, row {row + 1}/{self.rows}, "
                 f"scale x{self.scale:g}, speed x{self.speed:g}, {state}")
        self.frame_text = shape_chart(self.shapes(row), title=title, xlabel=spec.unit_system.length,
                                      width=width, height=height, color=self.color, xlim=xlim, ylim=ylim)
        self.update(Text.from_ansi(self.frame_text, no_wrap=True) if self.color
                    else Text(self.frame_text, no_wrap=True))

    def on_resize(self) -> None:
        self.draw()

    def watch_row(self) -> None:
        self.draw()

    def watch_scale(self) -> None:
        self._limits = None
        self.draw()

    # ----- keys -----
    def action_play(self) -> None:
        if self.playing:
            self.pause()
        elif self.trace is not None:
            self.playing = True
            self._timer = self.set_interval(1.0 / FPS, self._tick)
        self.draw()

    def pause(self) -> None:
        self.playing = False
        if self._timer is not None:
            self._timer.stop()
            self._timer = None

    @property
    def rows_per_tick(self) -> float:
        return max(self.rows / (PLAY_SECONDS * FPS), 1.0 / FPS) * self.speed

    def _tick(self) -> None:
        if self.rows:
            self._phase += self.rows_per_tick
            advance = int(self._phase)
            self._phase -= advance
            if advance:
                self.row = (self.row + advance) % self.rows

    def action_speed(self, factor: float) -> None:
        self.speed = min(max(self.speed * factor, 1.0 / 16), 64.0)
        self.draw()

    def action_step(self, delta: int) -> None:
        if self.rows:
            self.pause()
            self.row = (self.row + delta) % self.rows

    def action_scale(self, factor: float) -> None:
        self.scale = min(max(self.scale * factor, 1.0 / 64), 4096.0)

    def action_first(self) -> None:
        self.pause()
        self.row = 0
