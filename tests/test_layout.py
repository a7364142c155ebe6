"""The package's layout stays as built: no import cycle, nothing imported from a rank above, no
private name crossing modules, no module over the size limit (``tools/layout.py``)."""

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _layout():
    spec = importlib.util.spec_from_file_location("layout", ROOT / "tools" / "layout.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["layout"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_no_cycle_no_arrow_up_no_private_import_no_big_module():
    r = _layout().analyse(ROOT)
    assert r["cycles"] == []
    assert r["upward"] == []
    assert r["private_imports"] == []
    assert r["over_limit"] == {}
    assert r["unranked"] == []


def test_the_analysis_sees_what_it_must(tmp_path):
    """A cycle hidden in a function, an upward import and a private import are all found."""
    pkg = tmp_path / "tunnelkit"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "geometry.py").write_text("def f():\n    from .design import g\n")
    (pkg / "design.py").write_text("from .geometry import f\nfrom .crlb import _h\n")
    (pkg / "crlb.py").write_text("def _h():\n    pass\n")
    r = _layout().analyse(tmp_path)
    assert r["cycles"] == [["tunnelkit.design", "tunnelkit.geometry"]]
    assert "tunnelkit.geometry -> tunnelkit.design" in r["upward"]
    assert r["private_imports"] == ["tunnelkit.design imports _h from tunnelkit.crlb"]
