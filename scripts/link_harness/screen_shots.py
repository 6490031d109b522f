"""Pictures of what the harness's terminal shows: a pyte screen painted to PNG and GIF.

The harness (`--shots DIR`) copies its pyte screen a few times a second after a stone and hands
the copies here. Each cell is painted as a block of CW x CH pixels in its background colour,
the half blocks (U+2580, U+2584) and the full block split as a terminal draws them, other
characters in Pillow's built-in bitmap font (enough to read the status line). The painting
follows ../shared/tools/ansi_view.py, with the colours pyte gives for the default foreground
and background chosen like a dark terminal's.

Needs Pillow (`pip install pillow`); imported only when shots are asked for.
"""

from PIL import Image, ImageDraw

DEFAULT_FG, DEFAULT_BG = (200, 200, 200), (0, 0, 0)
UPPER, LOWER, FULL = "\u2580", "\u2584", "\u2588"


def copy_screen(screen):
    """The screen's cells as plain tuples (char, fg, bg, reverse), row by row: a copy the
    parser thread can keep changing the screen after."""
    rows = []
    for y in range(screen.lines):
        line = screen.buffer[y]
        rows.append([(c.data, c.fg, c.bg, c.reverse) for c in (line[x] for x in range(screen.columns))])
    return rows


def colour(value, default):
    if isinstance(value, str) and len(value) == 6:
        try:
            return tuple(int(value[i : i + 2], 16) for i in (0, 2, 4))
        except ValueError:
            return default
    return default


def paint(cells, cw=8, ch=16):
    """The copied screen as an RGB image, CW x CH pixels a cell."""
    rows, cols = len(cells), len(cells[0]) if cells else 0
    image = Image.new("RGB", (cols * cw, rows * ch), DEFAULT_BG)
    draw = ImageDraw.Draw(image)
    half = ch // 2
    for y, line in enumerate(cells):
        y0 = y * ch
        for x, (data, fg, bg, reverse) in enumerate(line):
            fg, bg = colour(fg, DEFAULT_FG), colour(bg, DEFAULT_BG)
            if reverse:
                fg, bg = bg, fg
            x0, x1 = x * cw, x * cw + cw - 1
            if data == UPPER:
                draw.rectangle([x0, y0, x1, y0 + half - 1], fill=fg)
                draw.rectangle([x0, y0 + half, x1, y0 + ch - 1], fill=bg)
            elif data == LOWER:
                draw.rectangle([x0, y0, x1, y0 + half - 1], fill=bg)
                draw.rectangle([x0, y0 + half, x1, y0 + ch - 1], fill=fg)
            elif data == FULL:
                draw.rectangle([x0, y0, x1, y0 + ch - 1], fill=fg)
            else:
                if bg != DEFAULT_BG:
                    draw.rectangle([x0, y0, x1, y0 + ch - 1], fill=bg)
                if data.strip():
                    draw.text((x0, y0 + (ch - 11) // 2), data, fill=fg)
    return image


def save_png(cells, path, cw=8, ch=16):
    paint(cells, cw, ch).save(path, optimize=True)


def save_gif(frames, path, interval_s, cw=4, ch=8):
    """An animated GIF of the copied screens, `interval_s` apart, each reduced to an adaptive
    palette of its own (water is smooth gradients: 255 colours a frame look right)."""
    if not frames:
        return
    images = [paint(cells, cw, ch).quantize(colors=255, method=Image.Quantize.MEDIANCUT) for cells in frames]
    images[0].save(path, save_all=True, append_images=images[1:], duration=int(interval_s * 1000), loop=0, optimize=True)
