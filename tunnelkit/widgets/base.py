"""A slider panel wired to a pure figure callback, shared by every explorer."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import ipywidgets as widgets
import plotly.graph_objects as go

from .._validate import boolean, callable_, integer, positive, real, text

__all__ = ["Explorer", "checkbox", "float_slider", "int_slider", "slider_value"]


def slider_value(name: str | None, value, lo: float, hi: float, *, whole: bool = False):
    """``value`` checked against a slider's range before the slider exists (ipywidgets would
    clamp it silently, or fail with a ``TraitError`` naming no parameter): a real number (an
    integer when ``whole``) in ``[lo, hi]``, errors naming ``name``. ``name=None``: the value is
    unchecked (the explorer's own constant), the range still is."""
    if name is not None:
        text("name", name)
    whole = boolean("whole", whole)
    if whole:
        lo, hi = integer("lo", lo), integer("hi", hi)
    else:
        lo, hi = real("lo", lo), real("hi", hi)
    if hi <= lo:
        raise ValueError(f"hi: must be above lo = {lo:g}, got {hi:g}")
    if name is None:
        return value
    if whole:
        return integer(name, value, minimum=lo, maximum=hi)
    x = real(name, value)
    if not lo <= x <= hi:
        raise ValueError(f"{name}: must lie in [{lo:g}, {hi:g}] (the slider's range), got {x:g}")
    return x


def float_slider(
    description: str,
    value: float,
    lo: float,
    hi: float,
    step: float,
    *,
    readout_format: str = ".3g",
    name: str | None = None,
) -> widgets.FloatSlider:
    """A FloatSlider that only reports on release (``continuous_update=False``); with ``name``
    (the explorer's parameter) ``value`` is checked against ``[lo, hi]`` first
    (:func:`slider_value`)."""
    value = slider_value(name, value, lo, hi) if name is not None else real("value", value)
    slider_value(None, value, lo, hi)  # the range, also for the explorer's own constant
    description = text("description", description, empty=True)
    step = positive("step", step)
    readout_format = text("readout_format", readout_format)
    return widgets.FloatSlider(
        value=value,
        min=lo,
        max=hi,
        step=step,
        description=description,
        continuous_update=False,
        readout_format=readout_format,
        style={"description_width": "initial"},
        layout={"width": "340px"},
    )


def int_slider(
    description: str, value: int, lo: int, hi: int, step: int = 1, *, name: str | None = None
) -> widgets.IntSlider:
    """An IntSlider that only reports on release (``continuous_update=False``); ``name`` as in
    :func:`float_slider`."""
    value = (
        slider_value(name, value, lo, hi, whole=True)
        if name is not None
        else integer("value", value)
    )
    slider_value(None, value, lo, hi, whole=True)
    description = text("description", description, empty=True)
    step = integer("step", step, minimum=1)
    return widgets.IntSlider(
        value=value,
        min=lo,
        max=hi,
        step=step,
        description=description,
        continuous_update=False,
        style={"description_width": "initial"},
        layout={"width": "340px"},
    )


def checkbox(description: str, value: bool, *, name: str | None = None) -> widgets.Checkbox:
    """A Checkbox; the value must be a real ``True``/``False`` (errors name ``name``, else
    ``value``)."""
    description = text("description", description, empty=True)
    label = "value" if name is None else text("name", name)
    return widgets.Checkbox(value=boolean(label, value), description=description)


class Explorer:
    """Controls + a plotly ``FigureWidget`` redrawn by ``callback(**values) -> go.Figure``.

    The figure is computed with the initial values *before* display, so a page that connects late
    (Voila) shows the right state. ``set(name=value, ...)`` moves controls programmatically (tests,
    lecture scripts) and triggers the same redraw as a user would.
    """

    def __init__(
        self,
        callback: Callable[..., go.Figure],
        controls: Mapping[str, widgets.ValueWidget],
        *,
        columns: int = 3,
    ) -> None:
        self.callback = callable_("callback", callback)
        if not isinstance(controls, Mapping):
            raise TypeError(f"controls: expected a mapping name -> widget, got {controls!r:.40}")
        integer("columns", columns, minimum=1)
        self.controls = dict(controls)
        self.figure = go.FigureWidget(callback(**self.values))
        for w in self.controls.values():
            w.observe(self._on_change, names="value")
        boxes = list(self.controls.values())
        rows = [widgets.HBox(boxes[i : i + columns]) for i in range(0, len(boxes), columns)]
        self.widget = widgets.VBox([*rows, self.figure])

    @property
    def values(self) -> dict[str, Any]:
        """Current value of every control, by name."""
        return {k: w.value for k, w in self.controls.items()}

    def _on_change(self, _change) -> None:
        self.refresh()

    def refresh(self) -> None:
        """Recompute the figure from the current values and push it into the widget."""
        new = self.callback(**self.values)
        with self.figure.batch_update():
            same = len(new.data) == len(self.figure.data) and all(
                a.type == b.type for a, b in zip(new.data, self.figure.data)
            )
            if same:
                for old, tr in zip(self.figure.data, new.data):
                    old.update(tr.to_plotly_json(), overwrite=True)
            else:
                self.figure.data = ()
                self.figure.add_traces(list(new.data))
            self.figure.layout.annotations = ()
            self.figure.layout.shapes = ()
            self.figure.update_layout(new.layout.to_plotly_json())

    def set(self, **values: Any) -> None:
        """Move controls by name, e.g. ``explorer.set(M=64)``; unknown names raise."""
        for k, v in values.items():
            if k not in self.controls:
                raise ValueError(f"{k}: no such control; controls are {sorted(self.controls)}")
            self.controls[k].value = v

    def _ipython_display_(self) -> None:  # pragma: no cover - display hook
        from IPython.display import display

        display(self.widget)
