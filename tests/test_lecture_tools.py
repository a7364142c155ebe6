"""Lecture tools without a browser or a kernel: notebook names, ports, servers stopped by pid,
figures read back from saved widget state, headline marks, static-site figure inlining, the
explorers view, the notebook/source sync check, HTML tables and per-method markers."""

from __future__ import annotations

import importlib.util
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import nbformat
import numpy as np
import plotly.graph_objects as go
import pytest

TOOLS = Path(__file__).resolve().parents[1] / "tools"
sys.path.insert(0, str(TOOLS))

import _lecture as lec  # noqa: E402


def load_tool(name: str):
    spec = importlib.util.spec_from_file_location(f"tk_tool_{name}", TOOLS / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture
def books(tmp_path):
    for stem in (
        "01-virtual-stations",
        "02-fresnel-bound",
        "02b-extra",
        "03-a-one",
        "03-a-two",
        "10-tenth",
    ):
        (tmp_path / f"{stem}.ipynb").write_text("{}")
    return tmp_path


def test_resolve_notebook_by_number_name_and_path(books):
    assert lec.resolve_notebook("01", books).name == "01-virtual-stations.ipynb"
    assert lec.resolve_notebook("1", books).name == "01-virtual-stations.ipynb"
    assert lec.resolve_notebook("02", books).name == "02-fresnel-bound.ipynb"  # not 02b-extra
    assert lec.resolve_notebook("10", books).name == "10-tenth.ipynb"
    assert lec.resolve_notebook("02-fresnel-bound", books).name == "02-fresnel-bound.ipynb"
    assert lec.resolve_notebook("02-fresnel-bound.ipynb", books).name == "02-fresnel-bound.ipynb"
    assert (
        lec.resolve_notebook(str(books / "10-tenth.ipynb")) == (books / "10-tenth.ipynb").resolve()
    )
    assert lec.list_notebooks(books)[0].name == "01-virtual-stations.ipynb"


def test_resolve_notebook_unknown_or_ambiguous_names_the_choices(books):
    with pytest.raises(lec.LectureError, match=r"'07' does not exist; .*01-virtual-stations"):
        lec.resolve_notebook("07", books)
    with pytest.raises(lec.LectureError, match="'03' is ambiguous"):
        lec.resolve_notebook("03", books)
    with pytest.raises(lec.LectureError, match="ambiguous"):
        lec.resolve_notebook("03-a", books)
    with pytest.raises(lec.LectureError, match="does not exist"):
        lec.resolve_notebook("nope", books)


def test_ports_free_and_in_use():
    port = lec.free_port()
    assert lec.check_port(port) == port
    with socket.socket() as s:
        s.bind((lec.HOST, 0))
        s.listen()
        taken = s.getsockname()[1]
        with pytest.raises(lec.LectureError, match=f"port {taken} on 127.0.0.1 is already in use"):
            lec.check_port(taken)
    with pytest.raises(lec.LectureError, match="out of range"):
        lec.check_port(70000)


def test_present_bad_input_exits_2_without_starting_anything(capsys):
    present = load_tool("present")
    assert present.main(["no-such-notebook"]) == 2
    assert "does not exist" in capsys.readouterr().err
    with socket.socket() as s:
        s.bind((lec.HOST, 0))
        s.listen()
        assert (
            present.main([lec.list_notebooks()[0].stem[:2], "--port", str(s.getsockname()[1])]) == 2
        )
    assert "already in use" in capsys.readouterr().err


def test_present_unknown_view_or_no_explorer_exits_2_writing_nothing(capsys, tmp_path, monkeypatch):
    present = load_tool("present")
    # the build directory of this test alone (the browser tests may present notebook 02 meanwhile)
    build = tmp_path / "build"
    monkeypatch.setattr(lec, "BUILD", build)
    monkeypatch.setattr(present, "BUILD", build)
    assert present.main(["02", "--view", "nonsense"]) == 2
    assert "unknown view 'nonsense'" in capsys.readouterr().err
    assert present.main(["99", "--view", "explorers"]) == 2
    assert "does not exist" in capsys.readouterr().err
    nb = nbformat.v4.new_notebook(
        cells=[nbformat.v4.new_code_cell("import tunnelkit as tk\ntk.setup_notebook()")]
    )
    path = tmp_path / "09-none.ipynb"
    nbformat.write(nb, path)
    with pytest.raises(lec.LectureError, match="no code cell tagged 'explorer'"):
        lec.explorers_notebook(path, tmp_path / "out")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    assert not build.exists(), sorted(build.rglob("*"))


def test_explorers_notebook_keeps_setup_and_tagged_cells_only(tmp_path):
    v4 = nbformat.v4
    cells = [
        v4.new_markdown_cell("# 09 · A chapter\n\ntext"),
        v4.new_code_cell("import tunnelkit as tk\ntk.setup_notebook()"),
        v4.new_code_cell("slow = sum(range(10))"),
        v4.new_code_cell("data = [1, 2]\nprint('noisy')", metadata={"tags": ["explorer-setup"]}),
        v4.new_markdown_cell("## Explore", metadata={"tags": ["explorer"]}),
        v4.new_code_cell("explorer(data)", metadata={"tags": ["explorer"]}),
        v4.new_markdown_cell("## Checks"),
        v4.new_code_cell("assert slow == 45"),
    ]
    path = tmp_path / "09-chapter.ipynb"
    nbformat.write(v4.new_notebook(cells=cells), path)
    out = lec.explorers_notebook(path, tmp_path / "present")
    assert out == tmp_path / "present" / "09-chapter.explorers.ipynb"
    got = nbformat.read(out, as_version=4)
    src = ["".join(c.source) for c in got.cells]
    assert src[0].startswith("# 09 · A chapter: the explorers")
    assert src[1:] == [
        "import tunnelkit as tk\ntk.setup_notebook()",
        "%%capture\ndata = [1, 2]\nprint('noisy')",
        "## Explore",
        "explorer(data)",
    ]
    assert [p.name for p in (tmp_path / "present").iterdir()] == [out.name]  # no temporary left


def _pair(root: Path, text: str) -> Path:
    """A notebooks/ folder with one notebook built from a percent source by check_notebooks."""
    (root / ".src").mkdir(parents=True)
    repo_config = lec.NOTEBOOKS / ".jupytext.toml"  # the workbook's own pairing
    (root / ".jupytext.toml").write_text(repo_config.read_text())
    (root / ".src" / "09-pair.py").write_text(text)
    return root / "09-pair.ipynb"


PAIRED = (
    "# %% [markdown]\n# # 09 · Pair\n\n# %%\nimport tunnelkit as tk\n\ntk.setup_notebook()\n\n"
    "# %% [markdown]\n# ## Checks\n\n# %%\nassert 1 + 1 == 2\n"
)


def test_notebook_and_source_sync_is_checked_and_rebuilt(tmp_path, capsys):
    check = load_tool("check_notebooks")
    nbdir = tmp_path / "notebooks"
    nb = _pair(nbdir, PAIRED)
    assert check.main(["--build", str(nbdir)]) == 0
    built = json.loads(nb.read_text())
    assert built["metadata"]["kernelspec"]["name"] == "python3"
    ids = [c["id"] for c in built["cells"]]
    capsys.readouterr()
    # the source changes, the notebook does not: a clear message naming both, exit 1, no write
    src = nbdir / ".src" / "09-pair.py"
    src.write_text(PAIRED.replace("1 + 1 == 2", "2 + 2 == 4"))
    stamp = nb.read_text()
    assert check.main([str(nbdir)]) == 1
    out = capsys.readouterr().out
    assert f"{nb}: disagrees with its source {src}" in out and "make format" in out
    assert nb.read_text() == stamp
    # --build brings it back in line, keeping the cell ids
    assert check.main(["--build", str(nbdir)]) == 0
    assert [c["id"] for c in json.loads(nb.read_text())["cells"]] == ids
    assert "2 + 2 == 4" in nb.read_text()
    # a wrong kernelspec and a source without a notebook are named too
    bad = json.loads(nb.read_text())
    bad["metadata"]["kernelspec"]["name"] = "tunnelkit"
    nb.write_text(json.dumps(bad, indent=1))
    (nbdir / ".src" / "10-orphan.py").write_text(PAIRED)
    capsys.readouterr()
    assert check.main([str(nbdir)]) == 1
    out = capsys.readouterr().out
    assert "kernelspec name 'tunnelkit', expected 'python3'" in out
    assert "10-orphan.py: a source without its notebook" in out


def test_tables_render_as_html_and_size_the_plotly_export():
    from tunnelkit.plots import javelin_table_figure, table

    t = javelin_table_figure(["a", "b"], [["x", 1.234], ["y", None]], title="T <1>")
    assert list(t.data[0].cells.values[1]) == ["1.23", "-"]
    html_text = t._repr_mimebundle_()["text/html"]
    assert html_text.count("<tr>") == 3 and "T &lt;1&gt;" in html_text
    assert '<td style="text-align:right">1.23</td>' in html_text  # numbers right-aligned
    short = table(["a"], [[1.0]] * 2).layout.height
    tall = table(["a"], [[1.0]] * 20).layout.height
    wrapped = table(["a", "b"], [["w" * 400, 1.0]] * 2).layout.height
    assert tall - short == 18 * 22 and wrapped > short
    with pytest.raises(ValueError, match=r"^rows: row 1 has 1 values for 2 columns"):
        table(["a", "b"], [[1, 2], [3]])
    from tunnelkit.plots import report_table
    from tunnelkit.reproduce import Report

    rep = Report("R", ["x", "y"], [["a", 0.5]], notes=["a note"], meta={"runs": 3})
    page = report_table(rep).to_html_table()
    assert "R (runs: 3)</caption>" in page and "<li>a note</li>" in page and page.count("<tr>") == 2


def test_methods_get_distinct_markers():
    from tunnelkit.plots.javelin import method_styles

    st = method_styles(["JAVELIN (ours)", "JAVELIN (paper)", "TeNFiLoc", "TeNFiLoc-N"])
    pairs = [(v["symbol"], v["color"]) for v in st.values()]
    assert len(set(pairs)) == 4 and len({v["symbol"] for v in st.values()}) == 4
    assert st["JAVELIN (ours)"]["symbol"] == "circle-open" and st["TeNFiLoc"]["symbol"] == "x"


def test_execute_keeps_the_callers_environment(tmp_path, monkeypatch):
    """The kernel sees the caller's environment (PATH, PYTHONPATH, ...) plus quick mode and the
    solutions run at once (the static site); a live kernel's solutions wait to be asked for."""
    monkeypatch.setattr(lec, "EXECUTED", tmp_path / "executed")
    monkeypatch.setenv("TK_ENV_MARK", "kept")
    monkeypatch.setenv("TUNNELKIT_SOLUTIONS", "0")
    path = tmp_path / "09-env.ipynb"
    code = (
        "import os\nprint(*(os.environ.get(v) for v in "
        "('TK_ENV_MARK', 'TUNNELKIT_QUICK', 'TUNNELKIT_SOLUTIONS')))"
    )
    nbformat.write(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)]), path)
    nb = lec.execute(path, quick=True, use_cache=False, timeout=120)
    assert nb.cells[0].outputs[0]["text"].strip() == "kept 1 1"
    assert os.environ["TUNNELKIT_SOLUTIONS"] == "0"
    live = lec.kernel_env(quick=False)
    assert "TUNNELKIT_SOLUTIONS" not in live and "TUNNELKIT_QUICK" not in live
    assert os.environ["TK_ENV_MARK"] == "kept" and "PATH" in os.environ  # restored afterwards


def test_stop_server_ends_the_process_and_its_children(tmp_path):
    pidfile = tmp_path / "child.pid"
    code = (
        "import subprocess, time, pathlib; c = subprocess.Popen(['sleep', '60']); "
        f"pathlib.Path({str(pidfile)!r}).write_text(str(c.pid)); time.sleep(60)"
    )
    proc = lec.start_server([sys.executable, "-c", code])
    for _ in range(100):
        if pidfile.exists() and pidfile.read_text():
            break
        time.sleep(0.05)
    child = int(pidfile.read_text())
    assert lec.child_pids(proc.pid) == [child] and lec.alive(child)
    lec.stop_server(proc, timeout=5)
    assert proc.poll() is not None
    assert not lec.alive(child, wait=5.0), "the server's child outlived it"


def test_wait_http_reports_a_server_that_died():
    proc = subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"])
    with pytest.raises(lec.LectureError, match="exited with code 3"):
        lec.wait_http(f"http://{lec.HOST}:{lec.free_port()}/", proc, timeout=20)


def test_serving_on_free_port_tries_again_when_the_port_was_taken(monkeypatch):
    """Another process takes the port between free_port() and the server's bind: the server exits
    with 'Address already in use' and the next attempt runs on a new port; a port held on every
    attempt ends in the error after ``attempts`` tries."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as held:
        held.bind((lec.HOST, 0))
        held.listen()
        taken = held.getsockname()[1]
        real = lec.free_port
        handed = iter([taken])
        monkeypatch.setattr(lec, "free_port", lambda: next(handed, None) or real())
        seen = []

        def http_server(port):
            seen.append(port)
            return [sys.executable, "-m", "http.server", str(port), "--bind", lec.HOST]

        with lec.serving_on_free_port(http_server, "", timeout=30) as (proc, base):
            assert proc.poll() is None
            assert base == f"http://{lec.HOST}:{seen[-1]}/"
        assert seen[0] == taken and len(seen) == 2 and seen[1] != taken
        assert proc.poll() is not None, "the server outlived its context"

        monkeypatch.setattr(lec, "free_port", lambda: taken)
        with (
            pytest.raises(lec.LectureError, match="exited with code"),
            lec.serving_on_free_port(http_server, "", attempts=2, timeout=30),
        ):
            pass


def test_lab_command_puts_kernels_on_ipc_and_never_moves_the_port():
    cmd = lec.lab_command(8888, Path("/tmp"))
    assert lec.IPC_TRANSPORT_FLAG in cmd and "--ServerApp.port_retries=0" in cmd


def _saved_widget_notebook(fw: go.FigureWidget, holder, source: str):
    """An 'executed' notebook whose one cell displays ``holder`` (a widget containing fw)."""
    from ipywidgets.embed import embed_data

    state = embed_data(views=[holder])["manager_state"]
    nb = nbformat.v4.new_notebook()
    out = nbformat.v4.new_output(
        "display_data",
        data={
            "text/plain": "VBox()",
            lec.WIDGET_MIME: {"model_id": holder.model_id, "version_major": 2},
        },
    )
    cell = nbformat.v4.new_code_cell(source, outputs=[out])
    nb.cells.append(cell)
    nb.metadata["widgets"] = {lec.WIDGET_STATE: state}
    return json.loads(json.dumps(nb))  # as saved: plain JSON, base64 buffers


def test_figurewidget_is_read_back_from_saved_state_with_its_arrays():
    import ipywidgets as widgets

    z = np.arange(12.0).reshape(3, 4) ** 1.5
    x = np.linspace(0.0, 1.0, 4)
    fw = go.FigureWidget(
        go.Heatmap(z=z, x=x, y=np.array([1.0, 2.0, 3.0])),
        layout={"title": {"text": "explorer"}, "height": 321},
    )
    holder = widgets.VBox([widgets.IntSlider(description="M"), fw])
    nb = nbformat.from_dict(_saved_widget_notebook(fw, holder, "# headline: the-map\nexplorer"))
    (found,) = lec.figures_of(nb)
    assert found.widget and found.headline == "the-map" and (found.cell, found.output) == (0, 0)
    trace = found.figure["data"][0]
    np.testing.assert_allclose(np.asarray(trace["z"], float), z, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.asarray(trace["x"], float), x, rtol=0, atol=1e-15)
    assert found.figure["layout"]["title"]["text"] == "explorer"
    assert found.figure["layout"]["height"] == 321
    # a change made after display travels as a delta: the saved state misses it, the dump has it
    fw.update_layout(title="moved")
    saved = nbformat.from_dict(_saved_widget_notebook(fw, holder, "explorer"))
    assert lec.figures_of(saved)[0].figure["layout"]["title"]["text"] == "explorer"
    saved.metadata["tunnelkit_lecture"] = {"figure_widgets": {fw.model_id: fw.to_plotly_json()}}
    assert lec.figures_of(saved)[0].figure["layout"]["title"]["text"] == "moved"


def test_headline_marks_and_file_names():
    figures = load_tool("figures")
    nb = nbformat.v4.new_notebook()
    fig = go.Figure(go.Scatter(x=[1, 2], y=[3, 4])).to_plotly_json()
    for src in (
        "fig_a.show()",
        "# headline: crlb-map\nfig_b.show()\nfig_c.show()",
        "# headline:bad name\n",
    ):
        outs = [nbformat.v4.new_output("display_data", data={lec.PLOTLY_MIME: fig})] * src.count(
            "show"
        )
        nb.cells.append(nbformat.v4.new_code_cell(src, outputs=outs))
    found = lec.figures_of(nb)
    assert [f.headline for f in found] == [None, "crlb-map", "crlb-map"]
    assert [n for n, _ in figures.headline_files(found)] == ["crlb-map", "crlb-map-2"]
    assert [n for n, _ in figures.headline_files(found[:1])] == ["fig01"]
    assert figures.size_of({"layout": {"height": 380}}, 1100, 600) == (1100, 380)


def test_site_inlines_figures_without_a_cdn():
    site = load_tool("site")
    nb = nbformat.v4.new_notebook()
    fig = go.Figure(go.Scatter(x=[1, 2], y=[3, 4], name="line")).to_plotly_json()
    nb.cells.append(
        nbformat.v4.new_code_cell(
            "f.show()",
            outputs=[
                nbformat.v4.new_output(
                    "display_data",
                    data={lec.PLOTLY_MIME: fig, "text/html": "<script src='https://x'>"},
                )
            ],
        )
    )
    nb.metadata["widgets"] = {lec.WIDGET_STATE: {"state": {}}}
    assert site.inline_figures(nb, "07") == 1
    out = nb.cells[0].outputs[0]
    assert list(out["data"]) == ["text/html"]
    page = out["data"]["text/html"]
    assert "Plotly.newPlot" in page and 'id="fig-07-0-0-0"' in page and "https://" not in page
    assert "widgets" not in nb.metadata


def test_site_inlines_explorers_as_snapshots_with_a_note():
    import ipywidgets as widgets

    site = load_tool("site")
    fw = go.FigureWidget(go.Scatter(x=[1, 2], y=[3, 4]))
    with_fig = nbformat.from_dict(
        _saved_widget_notebook(fw, widgets.VBox([widgets.IntSlider(), fw]), "explorer")
    )
    assert site.inline_figures(with_fig, "02") == 1
    page = with_fig.cells[0].outputs[0]["data"]["text/html"]
    assert 'id="fig-02-0-0-0"' in page and "Plotly.newPlot" in page
    assert page.endswith("</p>") and "make present NB=02" in page
    slider = widgets.VBox([widgets.IntSlider()])
    no_fig = nbformat.from_dict(_saved_widget_notebook(fw, slider, "explorer"))
    assert site.inline_figures(no_fig, "02") == 0
    (only,) = no_fig.cells[0].outputs[0]["data"].values()
    assert "tk-static-note" in only and "Plotly.newPlot" not in only
    assert "widgets" not in with_fig.metadata and "widgets" not in no_fig.metadata


def test_site_drops_progress_bars():
    import ipywidgets as widgets

    site = load_tool("site")
    fw = go.FigureWidget(go.Scatter(x=[1, 2], y=[3, 4]))
    bar = widgets.HBox([widgets.HTML("runs"), widgets.FloatProgress(value=3, max=10)])
    nb = nbformat.from_dict(_saved_widget_notebook(fw, bar, "for r in tqdm(runs): ..."))
    nb.cells[0].outputs.append(nbformat.v4.new_output("stream", name="stdout", text="done\n"))
    assert site.inline_figures(nb, "05") == 0
    assert [o.get("text") for o in nb.cells[0].outputs] == ["done\n"]  # the bar is gone
    # a bar closed since it was displayed (tqdm's leave=False) is not in the saved state
    assert lec.is_progress_bar("no-such-model", {}) is True


def test_notebook_04_and_its_appendix_04b_resolve_and_04_has_an_explorers_view(tmp_path):
    """`make present NB=04` is the lesson, `NB=04b` its appendix; 04's explorers view keeps the
    epoch explorer and, output hidden, the cells it needs (the drive, the epoch, the tracker)."""
    assert lec.resolve_notebook("04").name == "04-javelin-tracking.ipynb"
    assert lec.resolve_notebook("04b").name == "04b-javelin-reproduction.ipynb"
    out = lec.explorers_notebook(lec.resolve_notebook("04"), tmp_path)
    src = ["".join(c.source) for c in nbformat.read(out, as_version=4).cells]
    assert "tk.setup_notebook()" in src[1]
    setup = [s for s in src if s.startswith("%%capture\n")]
    assert len(setup) == 3 and "collect_routes" in setup[0] and "ev_ml = " in setup[2]
    assert src[-1].startswith("explorer = epoch_explorer(drive_ml, ev_ml, k=k)")
    with pytest.raises(lec.LectureError, match="no code cell tagged 'explorer'"):
        lec.explorers_notebook(lec.resolve_notebook("04b"), tmp_path / "b")


def test_title_of_drops_markdown_emphasis_but_keeps_tex():
    nb = {"cells": [{"cell_type": "markdown", "source": "# 08 · How many for *your* `tunnel`?"}]}
    assert lec.title_of(nb, "x") == "08 · How many for your tunnel?"
    nb = {"cells": [{"cell_type": "markdown", "source": "# 02 · **Bold** $M_{\\max}$ bound"}]}
    assert lec.title_of(nb, "x") == "02 · Bold $M_{\\max}$ bound"
    assert lec.title_of({"cells": []}, "fallback") == "fallback"


def test_site_collapses_solution_cells():
    from nbconvert import HTMLExporter

    site = load_tool("site")
    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_markdown_cell("# 09 · x"),
        nbformat.v4.new_code_cell("print('shown')"),
        nbformat.v4.new_code_cell("print('answer')", metadata={"tags": ["solution"]}),
    ]
    exporter = HTMLExporter(
        template_name="lab",
        extra_template_paths=[str(site.TEMPLATE_DIR)],
        template_file="chapter.html.j2",
    )
    body, _ = exporter.from_notebook_node(nb, resources={"tk_mathjax": ""})
    assert body.count('<details class="tk-solution">') == 1
    details = body.split('<details class="tk-solution">', 1)[1].split("</details>", 1)[0]
    assert "answer" in details and "shown" not in details


def test_site_glossary_page_and_links():
    site = load_tool("site")
    text = (Path(__file__).resolve().parents[1] / "notebooks" / "GLOSSARY.md").read_text()
    page = site.glossary_html(text)
    assert '<a id="srs"></a>' in page and "sounding reference signal" in page
    body = '<a href="GLOSSARY.md#srs">SRS</a> and <a href="GLOSSARY.md">glossary</a>'
    assert site.glossary_links(body).count('href="glossary.html') == 2
