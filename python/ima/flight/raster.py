# SPDX-License-Identifier: Apache-2.0
"""A small line-plot renderer on Pillow (a dependency of matplotlib, so always there) for the
figure every launch draws (ima.flight.plot): panels of time series with ticks, grid, shaded
spans, dashed marks, rotated labels and a legend. It draws at twice the size and halves the
image at the end, which smooths lines and text as antialiasing would.

Coordinates given to Canvas and Panel are in pixels of the final image; data coordinates are
mapped into a panel's box by its limits."""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Sequence
from pathlib import Path

from PIL import Image, ImageDraw, ImageFont

SCALE = 2  # drawn at twice the size, then halved
# matplotlib's default colours, so that the figure reads as the others of the product
BLUE, GREEN, RED, PURPLE = (31, 119, 180), (44, 160, 44), (214, 39, 40), (148, 103, 189)
BLACK, GREY = (0, 0, 0), (176, 176, 176)
WHITE = (255, 255, 255)
FONT_PX = {"title": 15, "label": 12.5, "tick": 12.5, "legend": 10, "note": 8.75}
TICK_PX = 4.5  # outward tick length
MINUS = "\u2212"


def blend(color: tuple, alpha: float) -> tuple:
    """`color` at `alpha` over white (what every shade of these figures is drawn over)."""
    return tuple(round(255 + (c - 255) * alpha) for c in color)


def _font_file() -> str | None:
    """DejaVu Sans as matplotlib ships it (found without importing matplotlib)."""
    spec = importlib.util.find_spec("matplotlib")
    for d in (spec.submodule_search_locations or []) if spec else []:
        path = Path(d) / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
        if path.is_file():
            return str(path)
    return None


_fonts: dict[float, ImageFont.ImageFont] = {}


def font(px: float):
    f = _fonts.get(px)
    if f is None:
        path, size = _font_file(), round(px * SCALE)
        f = ImageFont.truetype(path, size) if path else ImageFont.load_default(size)
        _fonts[px] = f
    return f


def nice_ticks(lo: float, hi: float, most: int = 7) -> tuple[list[float], int]:
    """Round tick values within [lo, hi] (steps of 1, 2, 2.5 or 5 times a power of ten, at most
    `most` of them) and the decimals their labels need."""
    span = hi - lo
    if not span > 0 or not math.isfinite(span):
        return [lo], 0
    raw = span / (most - 1)
    mag = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 2.5, 5.0, 10.0):
        if m * mag >= raw:
            step = m * mag
            break
    first = math.ceil(lo / step - 1e-9)
    ticks = []
    k = first
    while k * step <= hi + step * 1e-9:
        ticks.append(k * step)
        k += 1
    decimals = max(0, -math.floor(math.log10(step) + 1e-9) + (1 if m == 2.5 else 0))
    return ticks, decimals


def label(v: float, decimals: int) -> str:
    s = f"{v:.{decimals}f}"
    if float(s) == 0:
        s = s.lstrip("-")
    return s.replace("-", MINUS)


class Canvas:
    def __init__(self, width: int, height: int) -> None:
        self.width, self.height = width, height
        self.img = Image.new("RGB", (width * SCALE, height * SCALE), WHITE)
        self.draw = ImageDraw.Draw(self.img)

    def text(self, xy: tuple[float, float], s: str, px: float, fill=BLACK,
             anchor: str = "la") -> None:
        self.draw.text((xy[0] * SCALE, xy[1] * SCALE), s, fill=fill, font=font(px),
                       anchor=anchor)

    def vtext(self, x: float, y: float, s: str, px: float, fill=BLACK,
              align: str = "middle") -> None:
        """Text reading upwards (rotated 90°) with its right edge at x; its middle at y
        (align "middle") or its top at y ("top")."""
        f = font(px)
        box = f.getbbox(s)
        w, h = max(1, box[2] - box[0]), max(1, box[3] - box[1])
        mask = Image.new("L", (w, h), 0)
        ImageDraw.Draw(mask).text((-box[0], -box[1]), s, fill=255, font=f)
        mask = mask.transpose(Image.Transpose.ROTATE_90)
        left = round(x * SCALE) - mask.width
        top = round(y * SCALE) - (mask.height // 2 if align == "middle" else 0)
        self.img.paste(Image.new("RGB", mask.size, fill), (left, top), mask)

    def title(self, s: str) -> None:
        self.text((self.width / 2, 10), s, FONT_PX["title"], anchor="mt")

    def save(self, out: Path) -> None:
        self.img.reduce(SCALE).save(out, "PNG", compress_level=6)


class Panel:
    """One plot in `box` (left, top, right, bottom pixels), x over `xlim` and y over `ys`,
    each with a 5% margin on both sides (as matplotlib draws them)."""

    def __init__(self, canvas: Canvas, box: tuple[float, float, float, float],
                 xlim: tuple[float, float], ys: Sequence[float]) -> None:
        self.c, self.box = canvas, box
        x0, x1 = xlim
        x1 = x1 if x1 > x0 else x0 + 1.0
        self.xlim = (x0 - (x1 - x0) * 0.05, x1 + (x1 - x0) * 0.05)
        finite = [v for v in ys if math.isfinite(v)]
        lo, hi = (min(finite), max(finite)) if finite else (0.0, 1.0)
        pad = (hi - lo) * 0.05 if hi > lo else max(abs(lo) * 0.05, 1.0)
        self.ylim = (lo - pad, hi + pad)
        self.xticks = nice_ticks(*self.xlim, most=9)
        self.yticks = nice_ticks(*self.ylim, most=8)

    # data to drawing coordinates (the canvas's doubled pixels)
    def px(self, x: float) -> float:
        left, _, right, _ = self.box
        x0, x1 = self.xlim
        return (left + (x - x0) / (x1 - x0) * (right - left)) * SCALE

    def py(self, y: float) -> float:
        _, top, _, bottom = self.box
        y0, y1 = self.ylim
        return (bottom - (y - y0) / (y1 - y0) * (bottom - top)) * SCALE

    def _clip_x(self, x: float) -> float:
        return min(max(x, self.xlim[0]), self.xlim[1])

    def xspan(self, x0: float, x1: float, color, alpha: float) -> None:
        x0, x1 = self._clip_x(x0), self._clip_x(x1)
        if x1 > x0:
            _, top, _, bottom = self.box
            self.c.draw.rectangle((self.px(x0), top * SCALE, self.px(x1), bottom * SCALE),
                                  fill=blend(color, alpha))

    def grid(self) -> None:
        left, top, right, bottom = self.box
        color, d = blend(GREY, 0.6), self.c.draw
        for x in self.xticks[0]:
            d.line((self.px(x), top * SCALE, self.px(x), bottom * SCALE), fill=color, width=1)
        for y in self.yticks[0]:
            d.line((left * SCALE, self.py(y), right * SCALE, self.py(y)), fill=color, width=1)

    def line(self, xs: Sequence[float], ys: Sequence[float | None], color,
             width: float = 1.0) -> None:
        """A polyline, broken where a value is missing (None: not a number in the trace)."""
        run: list[tuple[float, float]] = []
        px, py, d, w = self.px, self.py, self.c.draw, round(width * SCALE)
        for x, y in zip(xs, ys, strict=True):
            if y is None:
                if len(run) > 1:
                    d.line(run, fill=color, width=w)
                run = []
            else:
                run.append((px(x), py(y)))
        if len(run) > 1:
            d.line(run, fill=color, width=w)
        elif run:
            d.point(run, fill=color)

    def _dashed(self, a: float, b: float, fixed: float, horizontal: bool, color,
                dash: tuple[float, float], width: float) -> None:
        on, off = dash[0] * SCALE, dash[1] * SCALE
        d, w = self.c.draw, max(1, round(width * SCALE))
        s = a
        while s < b:
            e = min(s + on, b)
            d.line((s, fixed, e, fixed) if horizontal else (fixed, s, fixed, e), fill=color,
                   width=w)
            s += on + off

    def hline(self, y: float, x0: float, x1: float, color, dash=(5, 2), width=1.0) -> None:
        if self.ylim[0] <= y <= self.ylim[1]:
            x0, x1 = self._clip_x(x0), self._clip_x(x1)
            self._dashed(self.px(x0), self.px(x1), self.py(y), True, color, dash, width)

    def vline(self, x: float, color, alpha: float = 1.0, dash=(4, 2), width=1.0) -> None:
        if self.xlim[0] <= x <= self.xlim[1]:
            _, top, _, bottom = self.box
            self._dashed(top * SCALE, bottom * SCALE, self.px(x), False, blend(color, alpha),
                         dash, width)

    def frame(self, ylabel: str, xticks: bool) -> None:
        """The box, the ticks and their labels (x only if `xticks`), the y axis's name."""
        left, top, right, bottom = self.box
        c, d, s = self.c, self.c.draw, SCALE
        d.rectangle((left * s, top * s, right * s, bottom * s), outline=BLACK, width=s)
        tick = TICK_PX * s
        ticks, dec = self.yticks
        widest = 0.0
        for y in ticks:
            d.line((left * s - tick, self.py(y), left * s, self.py(y)), fill=BLACK, width=s)
            text = label(y, dec)
            widest = max(widest, font(FONT_PX["tick"]).getlength(text) / s)
            c.text((left - TICK_PX - 3, self.py(y) / s), text, FONT_PX["tick"], anchor="rm")
        ticks, dec = self.xticks
        for x in ticks:
            d.line((self.px(x), bottom * s, self.px(x), bottom * s + tick), fill=BLACK, width=s)
            if xticks:
                c.text((self.px(x) / s, bottom + TICK_PX + 3), label(x, dec), FONT_PX["tick"],
                       anchor="ma")
        c.vtext(left - TICK_PX - 6 - widest, (top + bottom) / 2, ylabel, FONT_PX["label"])

    def xlabel(self, s: str) -> None:
        left, _, right, bottom = self.box
        self.c.text(((left + right) / 2, bottom + TICK_PX + 20), s, FONT_PX["label"],
                    anchor="ma")

    def vlabel(self, x: float, s: str, color) -> None:
        """A note reading upwards beside x, from near the top of the panel."""
        if self.xlim[0] <= x <= self.xlim[1]:
            _, top, _, bottom = self.box
            self.c.vtext(self.px(x) / SCALE - 1, top + 0.02 * (bottom - top), s,
                         FONT_PX["note"], fill=color, align="top")

    def legend(self, entries: list[tuple[str, tuple, str]]) -> None:
        """In the upper left corner: (kind "line" | "dash" | "patch", colour, text)."""
        left, top, _, _ = self.box
        s, d, f = SCALE, self.c.draw, font(FONT_PX["legend"])
        row, sample, pad = 14, 22, 5
        width = pad * 3 + sample + max(f.getlength(t) / s for _, _, t in entries)
        x, y = left + 6, top + 6
        d.rounded_rectangle((x * s, y * s, (x + width) * s, (y + pad * 2 + row * len(entries)) * s),
                            radius=3 * s, fill=WHITE, outline=(204, 204, 204), width=s)
        for k, (kind, color, text) in enumerate(entries):
            cy = y + pad + row * k + row / 2
            x0, x1 = x + pad, x + pad + sample
            if kind == "patch":
                d.rectangle((x0 * s, (cy - 4) * s, x1 * s, (cy + 4) * s),
                            fill=blend(color, 0.25))
            elif kind == "dash":
                self._dashed(x0 * s, x1 * s, cy * s, True, color, (5, 2), 1.0)
            else:
                d.line((x0 * s, cy * s, x1 * s, cy * s), fill=color, width=s)
            self.c.text((x1 + pad, cy), text, FONT_PX["legend"], anchor="lm")
