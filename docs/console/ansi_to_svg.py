#!/usr/bin/env python3
"""A terminal screen captured with `tmux capture-pane -e -p` (text with SGR colour escapes) to an
SVG of the same cells: one <text> per run of equal style, monospace, 16 ANSI colours, bold.
Usage: ansi_to_svg.py SCREEN.ansi OUT.svg"""
import html
import re
import sys

PALETTE = ["#1e1e1e", "#cd3131", "#0dbc79", "#e5e510", "#2472c8", "#bc3fbc", "#11a8cd", "#e5e5e5",
           "#666666", "#f14c4c", "#23d18b", "#f5f543", "#3b8eea", "#d670d6", "#29b8db", "#ffffff"]
FG, BG = "#d4d4d4", "#1e1e1e"
CELL_W, CELL_H, FONT = 8.4, 17, 14
SGR = re.compile(r"\x1b\[([0-9;]*)m")


def apply(style, params):
    codes = [int(c) if c else 0 for c in params.split(";")] if params else [0]
    i = 0
    while i < len(codes):
        c = codes[i]
        if c == 0:
            style = {"fg": None, "bg": None, "bold": False, "dim": False}
        elif c == 1:
            style["bold"] = True
        elif c == 2:
            style["dim"] = True
        elif c in (22,):
            style["bold"] = style["dim"] = False
        elif 30 <= c <= 37:
            style["fg"] = PALETTE[c - 30]
        elif 90 <= c <= 97:
            style["fg"] = PALETTE[c - 90 + 8]
        elif 40 <= c <= 47:
            style["bg"] = PALETTE[c - 40]
        elif 100 <= c <= 107:
            style["bg"] = PALETTE[c - 100 + 8]
        elif c == 39:
            style["fg"] = None
        elif c == 49:
            style["bg"] = None
        elif c in (38, 48) and i + 2 < len(codes) and codes[i + 1] == 5:
            n = codes[i + 2]
            colour = PALETTE[n] if n < 16 else FG
            style["fg" if c == 38 else "bg"] = colour
            i += 2
        i += 1
    return style


def main(src, dst):
    lines = open(src, encoding="utf-8").read().rstrip("\n").split("\n")
    rows = []
    # tmux carries attributes over line ends, as a terminal does.
    style = {"fg": None, "bg": None, "bold": False, "dim": False}
    for line in lines:
        cells = []
        pos = 0
        for m in SGR.finditer(line):
            cells += [(ch, dict(style)) for ch in line[pos:m.start()]]
            style = apply(style, m.group(1))
            pos = m.end()
        cells += [(ch, dict(style)) for ch in line[pos:]]
        rows.append(cells)
    width = max(80, max(len(r) for r in rows))
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width * CELL_W + 16:.0f}" '
           f'height="{len(rows) * CELL_H + 16}" font-family="DejaVu Sans Mono, monospace" '
           f'font-size="{FONT}">', f'<rect width="100%" height="100%" fill="{BG}"/>']
    for y, cells in enumerate(rows):
        x = 0
        while x < len(cells):
            st = cells[x][1]
            end = x
            while end < len(cells) and cells[end][1] == st:
                end += 1
            text = "".join(ch for ch, _ in cells[x:end])
            px, py = 8 + x * CELL_W, 8 + y * CELL_H
            if st["bg"]:
                out.append(f'<rect x="{px:.1f}" y="{py}" width="{(end - x) * CELL_W:.1f}" '
                           f'height="{CELL_H}" fill="{st["bg"]}"/>')
            if text.strip():
                fg = st["fg"] or FG
                weight = ' font-weight="bold"' if st["bold"] else ""
                opacity = ' opacity="0.6"' if st["dim"] else ""
                out.append(f'<text x="{px:.1f}" y="{py + CELL_H - 4}" fill="{fg}"{weight}{opacity} '
                           f'xml:space="preserve" textLength="{(end - x) * CELL_W:.1f}">'
                           f'{html.escape(text)}</text>')
            x = end
    out.append("</svg>")
    open(dst, "w", encoding="utf-8").write("\n".join(out))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
