"""Write the headline figures of each notebook to PNG and SVG for slides (build/figures/).

    python tools/figures.py              # every notebook, full mode
    python tools/figures.py 02 --quick   # one notebook, small Monte-Carlo counts

A notebook declares a headline figure by a comment line in the code cell that displays it:

    # headline: mmax-vs-distance
    mmax_range_figure(...).show()

The figure (or an explorer's initial figure) shown by that cell is written to
``build/figures/<notebook>/<name>.png`` and ``.svg`` with plotly's ``write_images`` (kaleido drives
Debian's Chromium, /usr/bin/chromium). A notebook that marks none gets every figure it shows,
named ``fig01``, ``fig02``, ... Notebooks are executed headless; the executed copy is cached in
build/executed/ and shared with tools/site.py.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _lecture import (
    BUILD,
    CHROMIUM,
    FoundFigure,
    LectureError,
    die,
    execute,
    figures_of,
    list_notebooks,
    resolve_notebook,
)


def headline_files(figs: list[FoundFigure]) -> list[tuple[str, FoundFigure]]:
    """(file stem, figure): the marked headline figures, or every figure if none is marked."""
    marked = [f for f in figs if f.headline]
    if not marked:
        return [(f"fig{k + 1:02d}", f) for k, f in enumerate(figs)]
    out, seen = [], {}
    for f in marked:
        n = seen[f.headline] = seen.get(f.headline, 0) + 1
        out.append((f.headline if n == 1 else f"{f.headline}-{n}", f))
    return out


def size_of(fig: dict, default_width: int, default_height: int) -> tuple[int, int]:
    """Width and height in px: the figure's own layout size where it sets one."""
    lay = fig.get("layout", {})
    return int(lay.get("width") or default_width), int(lay.get("height") or default_height)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebooks", nargs="*", help="chapter numbers or names (default: all)")
    ap.add_argument(
        "--quick", action="store_true", help="TUNNELKIT_QUICK=1 (small Monte-Carlo counts)"
    )
    ap.add_argument("--timeout", type=int, default=3600, help="seconds per cell (default 3600)")
    ap.add_argument("--out", type=Path, default=BUILD / "figures", help="output folder")
    ap.add_argument("--width", type=int, default=1100, help="px, when the figure sets none")
    ap.add_argument("--height", type=int, default=600, help="px, when the figure sets none")
    ap.add_argument("--scale", type=float, default=2.0, help="PNG pixel density (2 = retina)")
    args = ap.parse_args(argv)
    try:
        books = (
            [resolve_notebook(n) for n in args.notebooks] if args.notebooks else list_notebooks()
        )
    except LectureError as exc:
        return die(str(exc))
    if not books:
        return die("no notebooks in notebooks/")
    browser = os.environ.setdefault("BROWSER_PATH", CHROMIUM)
    if not os.access(browser, os.X_OK):
        return die(f"{browser} is missing: kaleido needs Chromium (run `make chromium`)", 1)

    import plotly.io as pio

    t0 = time.perf_counter()
    figs, files, widths, heights = [], [], [], []
    for nb_path in books:
        try:
            nb = execute(nb_path, quick=args.quick, timeout=args.timeout)
        except LectureError as exc:
            return die(str(exc), 1)
        chosen = headline_files(figures_of(nb))
        marked = any(f.headline for _, f in chosen)
        print(
            f"{nb_path.stem}: {len(chosen)} figure(s)"
            + ("" if marked else " (no '# headline: <name>' cell: writing every figure)")
        )
        folder = args.out / nb_path.stem
        folder.mkdir(parents=True, exist_ok=True)
        for stem, f in chosen:
            w, h = size_of(f.figure, args.width, args.height)
            for ext in ("png", "svg"):
                figs.append(f.figure)
                files.append(folder / f"{stem}.{ext}")
                widths.append(w)
                heights.append(h)
    if figs:
        pio.write_images(
            figs, files, scale=args.scale, width=widths, height=heights, validate=False
        )
    for f in files:
        print(
            f"  wrote {f.relative_to(args.out.parent) if f.is_relative_to(args.out.parent) else f}"
        )
    print(
        f"{len(files)} file(s) in {args.out} ({time.perf_counter() - t0:.0f} s, "
        f"{'quick' if args.quick else 'full'} mode)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
