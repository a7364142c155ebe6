"""Execute every notebook and render a static HTML site (build/site/) with an index of the chapters.

    python tools/site.py            # full mode: the papers' Monte-Carlo counts
    python tools/site.py --quick    # TUNNELKIT_QUICK=1: small counts, as in CI
    python tools/site.py --quick 02 06   # only these chapters (the index lists only them)

Plotly figures stay interactive (zoom, pan, hover) without a kernel: each figure is written as a
``Plotly.newPlot`` call and plotly.js is shipped once in ``static/`` (no CDN). An explorer's live
figure is rendered as a static snapshot of its initial state, with a note that its sliders need a
kernel (``make present NB=..``). MathJax is shipped in ``static/mathjax`` from the
jupyter-server-mathjax package. Nothing on a page loads from outside the site.
"""

from __future__ import annotations

import argparse
import html
import shutil
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _lecture import (
    BUILD,
    NOTEBOOKS,
    WIDGET_MIME,
    LectureError,
    die,
    execute,
    is_progress_bar,
    list_notebooks,
    live_figures,
    output_figures,
    resolve_notebook,
    title_of,
    widget_states,
)

TEMPLATE_DIR = Path(__file__).resolve().parent / "site_template"
MATHJAX_URL = "static/mathjax/MathJax.js?config=TeX-AMS-MML_HTMLorMML-full,Safe"
# MathJax 2 from static/mathjax (jupyter-server-mathjax ships the STIX-Web fonts only), on the
# chapters and on the index (chapter titles carry TeX).
MATHJAX_HEAD = (
    r"""<script type="text/x-mathjax-config">
MathJax.Hub.Config({
  "HTML-CSS": { availableFonts: [], preferredFont: null, webFont: "STIX-Web", imageFont: null,
                /* MathJax's font probe loads url('about:blank'), a console error in Chromium */
                styles: { "@font-face": { "font-family": "MathJax_Blank", src: "local('MathJax_Blank')" } } },
  /* the hidden MathML kept for screen readers would fetch TeX fonts that are not shipped */
  NativeMML: { styles: {
    "@font-face /*1*/": { src: "local('MathJax_Caligraphic')" },
    "@font-face /*2*/": { src: "local('MathJax_Caligraphic')" },
    "@font-face /*3*/": { src: "local('MathJax_AMS')" },
    "@font-face /*4*/": { src: "local('MathJax_Script')" },
    "@font-face /*5*/": { src: "local('MathJax_Fraktur')" },
    "@font-face /*6*/": { src: "local('MathJax_Fraktur')" } } },
  TeX: { equationNumbers: { autoNumber: "AMS", useLabelIds: true } },
  tex2jax: { inlineMath: [["$", "$"], ["\\(", "\\)"]], displayMath: [["$$", "$$"], ["\\[", "\\]"]],
             processEscapes: true, processEnvironments: true },
  displayAlign: "center",
  messageStyle: "none"
});
</script>
"""
    + f'<script src="{MATHJAX_URL}"></script>\n'
)
STATIC_NOTE = (
    "Static snapshot of an interactive explorer: its sliders need a running kernel "
    "(JupyterLab, or <code>make present NB={nb}</code>)."
)


def plotly_html(fig: dict, div_id: str) -> str:
    """A div + ``Plotly.newPlot`` script for one figure (plotly.js is loaded by the page)."""
    import plotly.io as pio

    return pio.to_html(
        fig,
        include_plotlyjs=False,
        full_html=False,
        div_id=div_id,
        validate=False,
        config={"responsive": True, "displaylogo": False},
    )


def inline_figures(nb, chapter: str) -> int:
    """Turn plotly JSON and FigureWidget outputs into self-contained HTML outputs; return count."""
    states, live = widget_states(nb), live_figures(nb)
    count = 0
    for ci, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        bars = [
            o
            for o in cell.get("outputs", [])
            if WIDGET_MIME in o.get("data", {})
            and is_progress_bar(o["data"][WIDGET_MIME]["model_id"], states)
        ]
        if bars:  # a progress bar means nothing on a static page
            cell["outputs"] = [o for o in cell["outputs"] if not any(o is b for b in bars)]
        for oi, out in enumerate(cell.get("outputs", [])):
            figs, widget = output_figures(out, states, live)
            note = ""
            if widget:
                note = f'<p class="tk-static-note">{STATIC_NOTE.format(nb=chapter)}</p>'
                if not figs:  # a widget without a figure: say it needs a kernel instead of nothing
                    out["data"] = {"text/html": note}
                    continue
            if not figs:
                continue
            parts = [plotly_html(f, f"fig-{chapter}-{ci}-{oi}-{k}") for k, f in enumerate(figs)]
            out["data"] = {"text/html": "\n".join(parts) + note}
            out.setdefault("metadata", {})
            count += len(figs)
    nb.metadata.pop("widgets", None)  # no widget manager on a static page
    return count


def render_chapter(
    path: Path,
    out_dir: Path,
    quick: bool,
    prev: str | None,
    nxt: str | None,
    timeout: int = 3600,
) -> dict:
    """Execute one notebook and write its HTML page; return its index entry."""
    from nbconvert import HTMLExporter

    t0 = time.perf_counter()
    nb = execute(path, quick=quick, timeout=timeout)
    t_exec = time.perf_counter() - t0
    chapter = path.stem.split("-", 1)[0]
    n_figs = inline_figures(nb, chapter)
    exporter = HTMLExporter(
        template_name="lab",
        extra_template_paths=[str(TEMPLATE_DIR)],
        template_file="chapter.html.j2",
        mathjax_url=MATHJAX_URL,
        exclude_input_prompt=True,
        exclude_output_prompt=True,
    )
    mode = "quick mode (small Monte-Carlo counts)" if quick else "full mode"
    title = title_of(nb, path.stem)
    body, _ = exporter.from_notebook_node(
        nb,
        resources={
            "metadata": {"name": title},
            "tk_prev": prev,
            "tk_next": nxt,
            "tk_mathjax": MATHJAX_HEAD,
            "tk_mode": f"executed {time.strftime('%Y-%m-%d')}, {mode}",
        },
    )
    page = f"{path.stem}.html"
    (out_dir / page).write_text(glossary_links(body), encoding="utf-8")
    return {"page": page, "title": title, "figures": n_figs, "seconds": t_exec}


GLOSSARY = "GLOSSARY.md"
GLOSSARY_PAGE = "glossary.html"


def glossary_links(body: str) -> str:
    """The notebooks link their glossary page (``GLOSSARY.md#term``); the site's page is HTML."""
    return body.replace(f'href="{GLOSSARY}', f'href="{GLOSSARY_PAGE}')


def glossary_html(markdown_text: str) -> str:
    """The glossary page of the site, from notebooks/GLOSSARY.md (its anchors kept)."""
    import mistune

    body = mistune.html(markdown_text)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1.0">
<title>tunnelkit: glossary</title>
<link rel="icon" href="data:,">
{MATHJAX_HEAD}<style>
body {{ font-family: system-ui, sans-serif; max-width: 46em; margin: 3em auto; padding: 0 1em;
  line-height: 1.5; color: #222; }}
</style>
</head>
<body>
<p><a href="index.html">&#8962; all chapters</a></p>
{body}
</body>
</html>
"""


def index_html(entries: list[dict], quick: bool) -> str:
    """The landing page: one link per chapter."""
    mode = "quick mode (TUNNELKIT_QUICK=1, small Monte-Carlo counts)" if quick else "full mode"
    items = "\n".join(
        f'    <li><a href="{html.escape(e["page"])}">{html.escape(e["title"])}</a></li>'
        for e in entries
    )
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1.0">
<title>tunnelkit: the workbook</title>
<link rel="icon" href="data:,">
{MATHJAX_HEAD}<style>
body {{ font-family: system-ui, sans-serif; max-width: 46em; margin: 3em auto; padding: 0 1em;
  line-height: 1.5; color: #222; }}
li {{ margin: 0.4em 0; font-size: 1.1em; }}
.mode {{ color: #666; font-size: 0.9em; }}
</style>
</head>
<body>
<h1>tunnelkit: locating a vehicle in a road tunnel with one base station</h1>
<p>The executed notebooks of the workbook. Figures are interactive (zoom, pan, hover); the
explorers' sliders need a running kernel: open the notebooks in JupyterLab (<code>make lab</code>).</p>
<ol class="chapters">
{items}
</ol>
<p class="mode">Built {time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())} in {mode}.</p>
</body>
</html>
"""


def copy_static(out_dir: Path) -> None:
    """plotly.js and MathJax from the installed packages into ``static/``."""
    import jupyter_server_mathjax
    import plotly

    static = out_dir / "static"
    static.mkdir(parents=True, exist_ok=True)
    shutil.copy2(
        Path(plotly.__file__).parent / "package_data" / "plotly.min.js", static / "plotly.min.js"
    )
    mj = Path(jupyter_server_mathjax.__file__).parent / "static"
    # the pages use the HTML-CSS output in English: leave out the SVG output and the translations
    skip = shutil.ignore_patterns("SVG", "localization")
    shutil.copytree(mj, static / "mathjax", dirs_exist_ok=True, ignore=skip)


def _render(args: tuple) -> dict:
    return render_chapter(*args)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebooks", nargs="*", help="chapter numbers or names (default: all)")
    ap.add_argument(
        "--quick", action="store_true", help="TUNNELKIT_QUICK=1 (small Monte-Carlo counts)"
    )
    ap.add_argument("--timeout", type=int, default=3600, help="seconds per cell (default 3600)")
    ap.add_argument(
        "--out", type=Path, default=BUILD / "site", help="output folder (default build/site)"
    )
    ap.add_argument(
        "--jobs", type=int, default=2, help="notebooks executed in parallel (default 2)"
    )
    args = ap.parse_args(argv)
    try:
        books = [resolve_notebook(n) for n in args.notebooks] or list_notebooks()
    except LectureError as exc:
        return die(str(exc))
    if not books:
        return die("no notebooks in notebooks/")
    t0 = time.perf_counter()
    out = args.out.resolve()
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    copy_static(out)
    pages = [f"{b.stem}.html" for b in books]
    jobs = [
        (
            b,
            out,
            args.quick,
            pages[i - 1] if i else None,
            pages[i + 1] if i + 1 < len(pages) else None,
            args.timeout,
        )
        for i, b in enumerate(books)
    ]
    print(
        f"executing {len(books)} notebook(s) in {'quick' if args.quick else 'full'} mode -> {out}",
        flush=True,
    )
    entries = []
    with ProcessPoolExecutor(max_workers=max(1, min(args.jobs, len(jobs)))) as pool:
        futures = [pool.submit(_render, job) for job in jobs]
        for fut in as_completed(futures):  # report (and stop on) a failure as soon as it happens
            try:
                e = fut.result()
            except LectureError as exc:
                for other in futures:
                    other.cancel()
                return die(f"{exc}\n(the notebooks still running finish before the exit)", 1)
            print(
                f"  {e['page']}: {e['figures']} figure(s), executed in {e['seconds']:.1f} s",
                flush=True,
            )
            entries.append(e)
    entries.sort(key=lambda e: e["page"])
    (out / "index.html").write_text(index_html(entries, args.quick), encoding="utf-8")
    glossary = NOTEBOOKS / GLOSSARY
    if glossary.exists():
        (out / GLOSSARY_PAGE).write_text(glossary_html(glossary.read_text()), encoding="utf-8")
    size = sum(f.stat().st_size for f in out.rglob("*") if f.is_file())
    print(
        f"wrote {out}/index.html: {len(entries)} chapter(s), {size / 2**20:.1f} MiB, "
        f"{time.perf_counter() - t0:.0f} s",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
