"""The scenario schema written out: a commented TOML template of a family's values
(:func:`render_template`, behind :func:`tunnelkit.scenarios.template`) and the Markdown reference
of every family (:func:`to_markdown`, printed by ``tunnelkit scenarios doc`` and kept in the
README), both from the one spec of :mod:`tunnelkit.schema` that validates the files.
"""

from __future__ import annotations

from .schema import FAMILIES, Key, Table
from .schema.spec import number_text, shape_text

__all__ = ["render_template", "to_markdown"]


def _fmt(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
            m, e = f"{v:.12e}".split("e")
            return f"{m.rstrip('0').rstrip('.')}e{int(e)}"
        s = repr(v)
        return s if any(c in s for c in ".e") else s + ".0"
    if isinstance(v, list):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r} to TOML")  # pragma: no cover


def range_text(key: Key) -> str:
    """``"> 0"``, ``"[-90, 90]"``, ... (empty if unbounded)."""
    lo = f"> {number_text(key.gt)}" if key.gt is not None else None
    lo = f">= {number_text(key.ge)}" if key.ge is not None else lo
    hi = f"< {number_text(key.lt)}" if key.lt is not None else None
    hi = f"<= {number_text(key.le)}" if key.le is not None else hi
    if lo and hi:
        left = "(" if key.gt is not None else "["
        right = ")" if key.lt is not None else "]"
        return f"{left}{number_text(key.gt if key.gt is not None else key.ge)}, {number_text(key.lt if key.lt is not None else key.le)}{right}"
    return lo or hi or ""


def key_comment(key: Key) -> str:
    """One-line description: doc, unit, range, choices and default."""
    bits = [key.doc]
    if key.unit:
        bits.append(f"[{key.unit}]")
    r = range_text(key)
    if r:
        bits.append(f"range {r}")
    if key.choices and len(key.choices) > 1:
        bits.append("one of " + ", ".join(key.choices))
    if key.required:
        bits.append("required")
    elif key.has_default and key.type not in ("table",):
        bits.append(f"default {_fmt(key.default)}")
    else:
        bits.append("optional")
    return "; ".join([bits[0], *bits[1:]]) if len(bits) > 1 else bits[0]


def _render_absent(lines: list[str], spec: Table, full: str, indent: str = "#   ") -> None:
    """Document the keys of a table the template leaves out (commented, one line each)."""
    for k in spec.keys:
        lines.append(f"{indent}{k.name}: {key_comment(k)}")
        if k.table is not None:
            _render_absent(lines, k.table, f"{full}.{k.name}", indent + "  ")
    for v, ks in spec.variants.items():
        for k in ks:
            lines.append(f"{indent}{k.name} (kind = {v!r}): {key_comment(k)}")


def _render(lines: list[str], spec: Table, values: dict, path: str) -> None:
    kind = values.get("kind") if spec.variants else None
    scalars = [k for k in spec.allowed(kind) if k.type not in ("table", "tables")]
    subs = [k for k in spec.allowed(kind) if k.type in ("table", "tables")]
    for k in scalars:
        lines.append(f"# {key_comment(k)}")
        if k.name in values:
            lines.append(f"{k.name} = {_fmt(values[k.name])}")
        elif k.has_default:
            lines.append(f"# {k.name} = {_fmt(k.default)}")
        else:
            lines.append(f"# {k.name} = ")
    for v, ks in spec.variants.items():
        if v != kind and ks:
            lines.append(f"# with kind = {v!r} also:")
            lines += [f"#   {k.name}: {key_comment(k)}" for k in ks]
    for k in subs:
        full = f"{path}.{k.name}" if path else k.name
        v = values.get(k.name)
        if k.type == "table":
            if v is None and not k.required:
                lines += ["", f"# [{full}]  {key_comment(k)}; keys:"]
                _render_absent(lines, k.table, full)
                continue
            lines += ["", f"# {key_comment(k)}", f"[{full}]"]
            _render(lines, k.table, v or {}, full)
        else:
            lines += ["", f"# [[{full}]]  {key_comment(k)}; one table per item"]
            if not v:
                lines[-1] += ", keys:"
                _render_absent(lines, k.table, full)
            for j, item in enumerate(v or []):
                lines += [""] * (j > 0) + [f"[[{full}]]"]
                _render(lines, k.table, item, full)


def render_template(family: str, values: dict, header: str = "") -> str:
    """A commented TOML file of ``family`` holding ``values``, every key documented from the spec."""
    if not isinstance(family, str) or family not in FAMILIES:
        raise ValueError(f"family: expected one of {list(FAMILIES)}, got {family!r}")
    if not isinstance(values, dict):
        raise TypeError(
            f"values: expected a dict of the file's tables, got {type(values).__name__}"
        )
    if not isinstance(header, str):
        raise TypeError(f"header: expected text, got {type(header).__name__}")
    spec = FAMILIES[family]
    lines = [f"# {ln}" if ln else "#" for ln in header.splitlines()]
    lines.append(
        f"# Schema: {spec.doc}. Keys marked 'required' must be present; unknown keys are errors."
    )
    lines.append("")
    _render(lines, spec, values, "")
    return "\n".join(lines) + "\n"


def _md_rows(rows: list[str], spec: Table, path: str) -> None:
    for k in spec.keys:
        full = f"{path}.{k.name}" if path else k.name
        if k.type in ("table", "tables"):
            continue
        rows.append(_md_row(full, k, ""))
    for v, ks in spec.variants.items():
        for k in ks:
            rows.append(_md_row(f"{path}.{k.name}", k, f"kind = {v!r}: "))
    for k in spec.keys:
        if k.type in ("table", "tables"):
            full = f"{path}.{k.name}" if path else k.name
            rows.append(_md_row(full, k, ""))
            _md_rows(rows, k.table, full + ("[]" if k.type == "tables" else ""))


def _md_row(full: str, k: Key, prefix: str) -> str:
    typ = {
        "floats": "numbers",
        "ints": "integers",
        "strs": "strings",
        "tables": "array of tables",
    }.get(k.type, k.type)
    if k.shape:
        typ += " " + shape_text(k.shape)
    if k.choices:
        typ += ": " + " \\| ".join(f"`{c}`" for c in k.choices)
    need = (
        "required"
        if k.required
        else (f"`{_fmt(k.default)}`" if k.has_default and k.type != "table" else "optional")
    )
    return f"| `{full}` | {typ} | {k.unit} | {range_text(k)} | {need} | {prefix}{k.doc} |"


def to_markdown() -> str:
    """The schema of every family as Markdown tables (``data/scenarios/README.md``)."""
    out = []
    for fam in ("user", "italiano2026", "jiang2023", "halili2022"):
        spec = FAMILIES[fam]
        title = "`user` (no `paper` key)" if fam == "user" else f'`paper = "{fam}"`'
        out += [f"### {title}: {spec.doc}", ""]
        out += [
            "| key | type | unit | range | default | meaning |",
            "| --- | --- | --- | --- | --- | --- |",
        ]
        rows: list[str] = []
        _md_rows(rows, spec, "")
        out += [*rows, ""]
    return "\n".join(out)
