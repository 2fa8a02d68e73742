"""The report page of a deck (``--report``): one self-contained HTML file, ``<stem>.html``.

Everything a reader needs is inside the one file, so it opens offline, mails as one
attachment and prints: the run's metadata (tool version, build, date), its warnings, the
figures as inline SVG, the fixed-format tables and the headline figures, the comparison with
the published cells where the deck reproduces a published table, and the deck itself.  For
four-bar and slider-crank decks (and the optimum or best design of a sweep, an optimisation
or a synthesis of them) an animation of the mechanism over the crank cycle is drawn as inline
SVG moved by a few lines of JavaScript with a slider for the crank angle; the positions come
from the study's kernel (no kinematics is recomputed here).  Sweeps get the design-space map
of their summary; optimisations their convergence plot, the map of the designs evaluated and
the optimum's drawing.

No network, no external file: no ``<link>``, no ``src=`` to anything but inline data, no
fonts to fetch.  The page builder never prints; the command line reports the path written.
"""
from __future__ import annotations

import datetime as _dt
import hashlib
import html
import io
import json
import math
import platform
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

    from driver._deck import Deck, Params
    from driver._result import Result

__all__ = ["MAX_PAGE_BYTES", "Section", "build_page", "figure_svg", "mechanism_animation", "page_for_result",
           "page_for_sweep", "page_for_optimize", "page_for_synthesis", "write_report", "run_metadata"]

#: the page size the browser test holds every shipped report to [bytes] (the SVG figures are most of it)
MAX_PAGE_BYTES = 6_000_000
#: at most this many tidy rows are shown as an HTML table (the full table is in the CSV/Parquet)
MAX_TIDY_ROWS = 200
#: crank positions of the animation over one turn
ANIMATION_FRAMES = 180


@dataclass
class Section:
    """One part of the page: an anchor id, a heading and its HTML body."""

    id: str
    title: str
    body: str


def esc(text: Any) -> str:
    """``text`` as HTML text (every <, >, &, quote escaped)."""
    return html.escape(str(text), quote=True)


_GREEK = {"alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "theta": "θ", "mu": "μ", "rho": "ρ",
          "sigma": "σ", "tau": "τ", "varphi": "φ", "phi": "φ", "omega": "ω", "psi": "ψ"}
_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


def plain(label: str) -> str:
    """A figure label as HTML text: its mathtext symbols as Unicode (``$\\omega_2$`` -> ω₂) and
    an escaped ``\\$`` (deck text) as the dollar sign it stands for."""
    def math(m: re.Match) -> str:
        t = m.group(1)
        t = re.sub(r"\\overline\{([^{}]*)\}", r"mean(\1)", t)   # \overline{d^2}: the mean of d^2
        t = re.sub(r"\\sqrt\{([^{}]*)\}", "\u221a\\1", t)
        t = re.sub(r"\^\{?2\}?", "\u00b2", t)
        t = re.sub(r"\\([A-Za-z]+)", lambda g: _GREEK.get(g.group(1), g.group(1)), t)
        t = re.sub(r"_\{([0-9]+)\}|_([0-9])", lambda g: (g.group(1) or g.group(2)).translate(_SUB), t)
        return t.replace("{", "").replace("}", "")
    out = re.sub(r"(?<!\\)\$(.+?)(?<!\\)\$", math, label)
    return out.replace("\\$", "$")


# ----------------------------------------------------------------------------- metadata

def run_metadata() -> dict[str, str]:
    """Tool version, build (Python, numpy, the compiled kernels' file and checksum) and the date."""
    from driver import __version__
    meta = {"tool": f"mechanism-driver {__version__}"}
    try:
        import driver._kernels as k
        data = Path(k.__file__).read_bytes()
        meta["kernels"] = f"{Path(k.__file__).name} (sha256 {hashlib.sha256(data).hexdigest()[:12]})"
    except (ImportError, OSError):   # pragma: no cover - the driver cannot run without them
        meta["kernels"] = "not found"
    meta["build"] = (f"Python {platform.python_version()}, numpy {np.__version__}, "
                     f"{platform.system()} {platform.machine()}")
    meta["date"] = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
    return meta


# ----------------------------------------------------------------------------- figures

_SVG_HEAD = re.compile(r"^.*?(?=<svg\b)", re.S)


def figure_svg(fig: Any, label: str = "") -> str:
    """A matplotlib figure as inline SVG markup: text kept as text (small, searchable, prints
    sharply), no XML prolog, scaled to the page width; ``label`` is its accessible name."""
    from driver.plotting import SVG_SALT, style
    buf = io.StringIO()
    with style(**{"svg.hashsalt": SVG_SALT, "svg.fonttype": "none"}):
        fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
    svg = _SVG_HEAD.sub("", buf.getvalue(), count=1)
    width_px = round(fig.get_figwidth() * 110)   # a figure's fonts read the same whatever its size
    svg = re.sub(r'<svg\b([^>]*?)\swidth="[^"]*"\s+height="[^"]*"',
                 lambda m: f'<svg{m.group(1)} class="fig" style="max-width:{width_px}px" role="img" '
                           f'aria-label="{esc(label)}"', svg, count=1)
    return svg


def _figure_block(fig: Any, caption: str) -> str:
    caption = plain(caption)
    return f'<figure class="plot">{figure_svg(fig, caption)}<figcaption>{esc(caption)}</figcaption></figure>'


def _figures_html(result: Result, skip: Iterable[str] = ()) -> tuple[str, list[str]]:
    """Every figure of ``result`` drawn as inline SVG; and the figures that could not be drawn."""
    blocks, failed = [], []
    for f in result.figures:
        if f.name in skip:
            continue
        try:
            fig = f.draw()
        except Exception as exc:   # a figure that fails must not lose the page: say so on it
            failed.append(f"figure '{f.name}' could not be drawn: {exc.__class__.__name__}: {exc}")
            continue
        blocks.append(_figure_block(fig, f"{result.name}_{f.name}: {f.name.replace('_', ' ')}"))
    return "\n".join(blocks), failed


# ----------------------------------------------------------------------------- animation

def _box(pts: np.ndarray, pad_y: float = 0.0) -> list[float]:
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
    pad = 0.08 * span
    return [float(lo[0] - pad), float(lo[1] - pad - pad_y), float(hi[0] - lo[0] + 2 * pad),
            float(hi[1] - lo[1] + 2 * pad + 2 * pad_y)]


_ANIM_JS = r"""
(function(){
  var root = document.getElementById("%(id)s");
  var F = JSON.parse(root.querySelector("script[type='application/json']").textContent);
  var n = F.theta.length, el = function(s){ return root.querySelector("[data-part='" + s + "']"); };
  var crank = el("crank"), coupler = el("coupler"), out = el("out"), pa = el("A"), pb = el("B"),
      pp = el("P"), block = el("block"), note = el("note"), slider = root.querySelector("input[type=range]"),
      label = root.querySelector("output"), play = root.querySelector("button"), timer = null;
  function line(l, p, q){ l.setAttribute("x1", p[0]); l.setAttribute("y1", p[1]);
                          l.setAttribute("x2", q[0]); l.setAttribute("y2", q[1]); }
  function dot(c, p){ c.setAttribute("cx", p[0]); c.setAttribute("cy", p[1]); }
  function show(k){
    var A = F.A[k], B = F.B[k], ok = F.ok[k] === 1, G = F.ground;
    line(crank, G[0], A); dot(pa, A);
    label.textContent = F.theta[k].toFixed(0) + "\u00b0" + (F.phase ? " " + F.phase[k] : "");
    [coupler, out, pb, pp, block].forEach(function(e){ if (e) e.style.visibility = ok ? "visible" : "hidden"; });
    note.style.visibility = ok ? "hidden" : "visible";
    if (!ok) return;
    if (F.kind === "slider") {
      var dx = B[0] - A[0], dy = B[1] - A[1], L = Math.sqrt(dx * dx + dy * dy), b = F.bow ? 2 * F.bow[k] : 0;
      var C = [(A[0] + B[0]) / 2 - b * dy / L, (A[1] + B[1]) / 2 + b * dx / L];
      coupler.setAttribute("d", "M" + A.join(",") + " Q" + C.join(",") + " " + B.join(","));
    } else if (F.P) coupler.setAttribute("points", [A, B, F.P[k]].map(function(p){ return p.join(","); }).join(" "));
    else coupler.setAttribute("points", [A, B].map(function(p){ return p.join(","); }).join(" "));
    dot(pb, B);
    if (F.P) dot(pp, F.P[k]);
    if (F.kind === "rocker") line(out, G[1], B);
    else { var w = parseFloat(block.getAttribute("width")), h = parseFloat(block.getAttribute("height"));
           block.setAttribute("x", B[0] - w / 2); block.setAttribute("y", B[1] - h / 2); }
  }
  slider.addEventListener("input", function(){ show(parseInt(slider.value, 10)); });
  play.addEventListener("click", function(){
    if (timer) { clearInterval(timer); timer = null; play.textContent = "play"; return; }
    play.textContent = "pause";
    timer = setInterval(function(){
      slider.value = (parseInt(slider.value, 10) + 1) %% n; show(parseInt(slider.value, 10)); }, 40);
  });
  show(parseInt(slider.value, 10));
})();
"""


def mechanism_animation(params: Params, anim_id: str = "anim", caption: str = "",
                        result: Result | None = None) -> str | None:
    """The animation of a deck's mechanism over one crank turn (inline SVG, JSON positions from the
    study's ``Study.animation``, and a few lines of JavaScript), or None for a study without one.
    The positions' ``kind`` says what the crank drives: a coupler and a ``'rocker'`` (four-bar) or a
    rod and a ``'slider'`` (a slider-crank ``result`` adds its elastic rod's midpoint deflection,
    magnified, as ``bow``)."""
    from driver._study import load_study
    study = load_study(params.group)
    F = study.animation(params, result, ANIMATION_FRAMES) if study is not None and study.animation else None
    if F is None:
        return None
    F["box"] = _box(np.asarray(F.pop("box_points"), float), F.pop("pad_y", 0.0))
    x0, y0, w, h = F["box"]
    s = max(w, h)
    lw, rad = 0.012 * s, 0.014 * s
    flip = f"translate(0,{2 * y0 + h:.6g}) scale(1,-1)"   # y up, as the figures draw it
    ok = np.array(F["ok"], bool)
    paths = []
    if F.get("segments"):   # a rocking crank: per motion B's (and P's) loop, A's arc, the limits dashed
        for a, b in F["segments"]:
            for name, key, colour in (("path of B", "B", "#c0392b"), ("path of P", "P", "#8e44ad")):
                if F[key] is None:
                    continue
                d = " ".join(f"{p[0]:.5g},{p[1]:.5g}" for p in np.array(F[key])[a:b])
                paths.append(f'<polyline points="{d}" fill="none" stroke="{colour}" stroke-width="{lw / 3:.4g}" '
                             f'stroke-dasharray="{lw:.4g},{lw / 2:.4g}"><title>{name}</title></polyline>')
        g1 = F["ground"][1]
        for (lo, hi), rows in zip(F["limit_angles"], F["limits"]):
            for ang, r in zip((lo, hi), rows):
                d = f"0,0 {r[0]:.5g},{r[1]:.5g} {r[2]:.5g},{r[3]:.5g} {g1[0]:.5g},{g1[1]:.5g}"
                paths.append(f'<polyline data-part="limit" points="{d}" fill="none" stroke="#000" '
                             f'stroke-width="{lw / 4:.4g}" stroke-dasharray="{lw / 2:.4g},{lw / 2:.4g}">'
                             f'<title>limit position: crank angle {ang:.1f}\u00b0 (the crank reverses)</title></polyline>')
    elif ok.any():
        for name, key, colour in (("path of B", "B", "#c0392b"), ("path of P", "P", "#8e44ad")):
            if F[key] is None or (F["kind"] == "slider"):
                continue
            pts = np.array(F[key])
            runs = np.split(np.arange(len(ok)), np.flatnonzero(np.diff(ok.astype(int))) + 1)
            for run in runs:
                if ok[run[0]] and len(run) > 1:
                    closed = ok.all()
                    d = " ".join(f"{p[0]:.5g},{p[1]:.5g}" for p in pts[run])
                    tag = "polygon" if closed else "polyline"
                    paths.append(f'<{tag} points="{d}" fill="none" stroke="{colour}" stroke-width="{lw / 3:.4g}" '
                                 f'stroke-dasharray="{lw:.4g},{lw / 2:.4g}"><title>{name}</title></{tag}>')
    a_pts = np.array(F["A"])
    if F.get("segments"):   # the crank pin's arc, once per motion (the forward stroke covers it)
        a_path = "".join('<polyline points="' + " ".join(f"{p[0]:.5g},{p[1]:.5g}" for p in a_pts[a:(a + b) // 2]) +
                         f'" fill="none" stroke="#999" stroke-width="{lw / 4:.4g}"><title>path of A</title></polyline>'
                         for a, b in F["segments"])
    elif ok.all() or F["kind"] == "slider":
        a_path = ('<polygon points="' + " ".join(f"{p[0]:.5g},{p[1]:.5g}" for p in a_pts) + f'" fill="none" '
                  f'stroke="#999" stroke-width="{lw / 4:.4g}"><title>path of A</title></polygon>')
    else:   # a crank that cannot turn: its pin's path only where the linkage assembles
        runs = np.split(np.arange(len(ok)), np.flatnonzero(np.diff(ok.astype(int))) + 1)
        a_path = "".join('<polyline points="' + " ".join(f"{p[0]:.5g},{p[1]:.5g}" for p in a_pts[run]) +
                         f'" fill="none" stroke="#999" stroke-width="{lw / 4:.4g}"><title>path of A</title></polyline>'
                         for run in runs if ok[run[0]] and len(run) > 1)
    g0, g1 = F["ground"]
    pivots = "".join(f'<path d="M{p[0] - 2 * rad:.5g},{p[1] - 2.2 * rad:.5g} L{p[0] + 2 * rad:.5g},{p[1] - 2.2 * rad:.5g} '
                     f'L{p[0]:.5g},{p[1]:.5g} Z" fill="#555"/>' for p in ([g0, g1] if F["kind"] == "rocker" else [g0]))
    if F["kind"] == "rocker":
        guide = f'<line x1="{g0[0]}" y1="{g0[1]}" x2="{g1[0]}" y2="{g1[1]}" stroke="#555" stroke-width="{lw / 2:.4g}"/>'
        out = f'<line data-part="out" stroke="#e67e22" stroke-width="{lw:.4g}" stroke-linecap="round"/>'
        block = ""
    else:
        xs = np.array(F["B"])[:, 0]
        guide = (f'<line x1="{xs.min() - 0.1 * s:.5g}" y1="{-1.6 * rad:.5g}" x2="{xs.max() + 0.1 * s:.5g}" '
                 f'y2="{-1.6 * rad:.5g}" stroke="#555" stroke-width="{lw / 3:.4g}"/>')
        out = ""
        block = (f'<rect data-part="block" width="{6 * rad:.5g}" height="{3 * rad:.5g}" fill="#e67e22" '
                 f'fill-opacity="0.85" stroke="#333" stroke-width="{lw / 4:.4g}"/>')
    if F["kind"] == "slider":   # the rod: a curve A-B (bowed by the elastic deflection when known)
        coupler = (f'<path data-part="coupler" fill="none" stroke="#2980b9" stroke-width="{lw:.4g}" '
                   'stroke-linecap="round"/>')
    else:
        coupler = (f'<polygon data-part="coupler" fill="#3498db" fill-opacity="0.25" stroke="#2980b9" '
                   f'stroke-width="{lw:.4g}" stroke-linejoin="round"/>')
    if F.get("bow_note"):
        caption = (caption + " " if caption else "") + F["bow_note"][0].upper() + F["bow_note"][1:] + "."
    n = len(F["theta"])
    data = json.dumps(F, separators=(",", ":"))
    body = f"""
<div class="anim" id="{anim_id}">
<svg class="mech" viewBox="{x0:.6g} {y0:.6g} {w:.6g} {h:.6g}" role="img" aria-label="{esc(caption or 'mechanism')}">
 <g transform="{flip}">
  {guide}
  {a_path}
  {''.join(paths)}
  <line data-part="crank" stroke="#2c3e50" stroke-width="{lw:.4g}" stroke-linecap="round"/>
  {coupler}
  {out}{block}{pivots}
  <circle data-part="A" r="{rad:.4g}" fill="#fff" stroke="#000" stroke-width="{lw / 4:.4g}"/>
  <circle data-part="B" r="{rad:.4g}" fill="#fff" stroke="#000" stroke-width="{lw / 4:.4g}"/>
  {f'<circle data-part="P" r="{rad:.4g}" fill="#8e44ad"/>' if F["P"] is not None else ''}
 </g>
 <text data-part="note" x="{x0 + 0.02 * w:.5g}" y="{y0 + 0.06 * h:.5g}" font-size="{0.04 * s:.4g}" fill="#c0392b"
  style="visibility:hidden">the linkage cannot be assembled at this crank angle</text>
</svg>
<div class="controls"><button type="button">play</button>
<label>crank angle <input type="range" min="0" max="{n - 1}" step="1" value="0"></label> <output>0\u00b0</output></div>
<script type="application/json">{data}</script>
<script>{_ANIM_JS % {"id": anim_id}}</script>
{f'<p class="caption">{esc(caption)}</p>' if caption else ''}
</div>"""
    return body


# ----------------------------------------------------------------------------- tables

def _pre(text: str) -> str:
    return f"<pre>{esc(text)}</pre>"


def _kv_table(rows: dict[str, Any] | Sequence[tuple[str, Any]], cls: str = "kv") -> str:
    items = rows.items() if isinstance(rows, dict) else rows
    body = "".join(f"<tr><th>{esc(k)}</th><td>{esc(_fmt(v))}</td></tr>" for k, v in items)
    return f'<table class="{cls}">{body}</table>'


def _fmt(v: Any) -> str:
    if v is None:
        return "—"
    if isinstance(v, (float, np.floating)):
        return "—" if not math.isfinite(float(v)) else f"{float(v):.6g}"
    return str(v)


def _frame_table(frame: pd.DataFrame, limit: int = MAX_TIDY_ROWS, cls: str = "data") -> str:
    shown = frame.head(limit)
    head = "".join(f"<th>{esc(c)}</th>" for c in shown.columns)
    rows = "".join("<tr>" + "".join(f"<td>{esc(_fmt(v))}</td>" for v in r) + "</tr>"
                   for r in shown.itertuples(index=False, name=None))
    more = (f'<p class="note">first {limit} of {len(frame)} rows; the whole table is in the CSV/Parquet '
            "files (--csv, --format parquet)</p>") if len(frame) > limit else ""
    return f'<div class="scroll"><table class="{cls}"><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table></div>{more}'


def _warnings_html(warnings: Sequence[str]) -> str:
    if not warnings:
        return '<p class="ok">No warnings.</p>'
    return '<ul class="warn">' + "".join(f"<li>{esc(w)}</li>" for w in warnings) + "</ul>"


def _comparison_html(frame: pd.DataFrame | None, note: str = "") -> str:
    if frame is None or not len(frame):
        return f'<p class="note">{esc(note or "No published table belongs to this deck.")}</p>'
    counts = frame.groupby(["table", "status"]).size().unstack(fill_value=0)
    summary = _frame_table(counts.reset_index(), limit=100)
    off = frame[~frame["status"].isin(["identical", "agrees"])]
    detail = (_frame_table(off[["table", "row", "column", "printed", "computed", "status", "reason"]], limit=300)
              if len(off) else '<p class="ok">Every published cell is reproduced (identical or within half a '
                               'unit of its last printed digit).</p>')
    return (f"<p>{len(frame)} published cells compared; cells per table and status:</p>{summary}"
            f"<p>Cells that are not identical or within the printed precision:</p>{detail}")


# ----------------------------------------------------------------------------- page

_CSS = """
:root { --ink:#1b1b1b; --muted:#5b5b5b; --rule:#d0d0d0; --accent:#1f4e79; }
* { box-sizing: border-box; }
body { font: 15px/1.45 "DejaVu Sans", "Segoe UI", Helvetica, Arial, sans-serif; color: var(--ink);
       max-width: 1100px; margin: 0 auto; padding: 1.2em 1.5em 3em; }
h1 { font-size: 1.6em; margin: 0.2em 0 0.1em; color: var(--accent); }
h2 { font-size: 1.25em; margin-top: 1.8em; border-bottom: 1px solid var(--rule); padding-bottom: 0.15em; }
p.sub { color: var(--muted); margin-top: 0; }
nav ul { list-style: none; padding: 0; display: flex; flex-wrap: wrap; gap: 0.3em 1.2em; }
nav a { color: var(--accent); text-decoration: none; }
table { border-collapse: collapse; font-size: 0.88em; margin: 0.5em 0; }
th, td { border: 1px solid var(--rule); padding: 0.15em 0.5em; text-align: left; vertical-align: top; }
table.data td { font-variant-numeric: tabular-nums; text-align: right; white-space: nowrap; }
table.kv th { background: #f4f4f4; font-weight: 600; }
thead th { background: #f4f4f4; position: sticky; top: 0; }
div.scroll { max-height: 32em; overflow: auto; }
pre { font: 12px/1.3 "DejaVu Sans Mono", Menlo, Consolas, monospace; background: #fafafa;
      border: 1px solid var(--rule); padding: 0.6em; overflow-x: auto; }
figure.plot { margin: 1em 0; break-inside: avoid; }
figure.plot svg.fig { width: 100%; height: auto; max-width: 1000px; display: block; }
figcaption, p.caption, p.note { color: var(--muted); font-size: 0.88em; }
ul.warn li { color: #8a4b00; }
p.ok { color: #216e39; }
.anim { break-inside: avoid; }
.anim svg.mech { width: 100%; max-width: 760px; height: auto; max-height: 70vh; border: 1px solid var(--rule);
                 background: #fff; display: block; }
.controls { margin: 0.4em 0; display: flex; gap: 1em; align-items: center; }
.controls input[type=range] { width: 22em; vertical-align: middle; }
details > summary { cursor: pointer; color: var(--accent); }
@media print {
  body { max-width: none; font-size: 11pt; padding: 0; }
  nav, .controls, button { display: none; }
  div.scroll { max-height: none; overflow: visible; }
  h2 { break-after: avoid; }
  details { display: block; }
  details > summary { display: none; }
  pre { white-space: pre-wrap; font-size: 8pt; }
}
"""


def build_page(title: str, subtitle: str, sections: Sequence[Section], meta: dict[str, str]) -> str:
    """The whole page: head with the style sheet, the title, a contents line and the sections."""
    nav = "".join(f'<li><a href="#{esc(s.id)}">{esc(s.title)}</a></li>' for s in sections)
    body = "\n".join(f'<section id="{esc(s.id)}"><h2>{esc(s.title)}</h2>\n{s.body}\n</section>' for s in sections)
    metas = _kv_table(meta)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="{esc(meta.get('tool', 'mechanism-driver'))}">
<title>{esc(title)}</title>
<style>{_CSS}</style>
</head>
<body>
<header>
<h1>{esc(title)}</h1>
<p class="sub">{esc(subtitle)}</p>
<nav><ul>{nav}<li><a href="#run">run</a></li></ul></nav>
</header>
<main>
{body}
<section id="run"><h2>run</h2>{metas}</section>
</main>
</body>
</html>
"""


def _deck_text(deck: Deck | None, params: Params | None = None) -> str:
    """The deck as its file says it (or, for a deck given in Python, its groups as namelists)."""
    if deck is not None:
        path = Path(deck.path)
        try:
            if path.is_file() and path.stat().st_size < 2_000_000:
                return path.read_text(errors="replace")
        except OSError:
            pass
        lines = []
        for g in deck.groups.values():
            lines.append(f"&{g.name}")
            lines += [f"  {k} = {v!r}" for k, v in g.values.items()]
            lines.append("/")
        return "\n".join(lines) + "\n"
    if params is not None:
        return f"&{params.group}\n" + "".join(f"  {k} = {v!r}\n" for k, v in params.items() if k in params.given) + "/\n"
    return ""


def _result_sections(result: Result, params: Params | None, comparison: pd.DataFrame | None,
                     comparison_note: str = "", anim_caption: str = "") -> tuple[list[Section], list[str]]:
    sections = []
    notes: list[str] = []
    if params is not None:
        anim = mechanism_animation(params, f"anim-{re.sub(r'[^A-Za-z0-9]', '', result.name) or 'x'}",
                                   anim_caption or "The mechanism over one crank turn (positions from the kernel); "
                                   "drag the slider or press play.", result=result)
        if anim:
            sections.append(Section("animation", "animation over the crank cycle", anim))
    figs, failed = _figures_html(result)
    notes += failed
    if figs:
        sections.append(Section("figures", "figures", figs))
    if result.summary:
        sections.append(Section("summary", "headline figures", _kv_table(result.summary)))
    sections.append(Section("published", "comparison with the published tables",
                            _comparison_html(comparison, comparison_note)))
    tables = _pre(result.text)
    for suffix, text in result.extra.items():
        tables += f"<details><summary>{esc(result.name + suffix)}</summary>{_pre(text)}</details>"
    sections.append(Section("tables", "tables (.out)", tables))
    if result.tidy is not None and len(result.tidy):
        sections.append(Section("tidy", "tidy table", _frame_table(result.tidy)))
    return sections, notes


def page_for_result(result: Result, deck: Deck | None = None, params: Params | None = None,
                    compare: bool = True) -> str:
    """The page of one single-case run: ``result`` as the runner returned it, the ``deck`` it
    ran (for the echo) and its validated ``params`` (for the animation and the comparison)."""
    comparison, note = None, ""
    if compare and params is not None:
        from driver._compare import compare_result
        try:
            comparison = compare_result(deck.path if deck is not None else Path(result.name), params, result)
        except Exception as exc:   # a comparison that fails is reported on the page, not fatal
            note = f"the comparison could not be made: {exc.__class__.__name__}: {exc}"
    sections, notes = _result_sections(result, params, comparison, note)
    warnings = list(result.warnings) + notes
    if result.failure:
        warnings.insert(0, f"the run failed: {result.failure}")
    sections.insert(0, Section("warnings", "warnings", _warnings_html(warnings)))
    sections.append(Section("deck", "deck", _pre(_deck_text(deck, params))))
    title = f"{result.name}: {result.study}"
    sub = _subtitle(result.study, params)
    return build_page(title, sub, sections, run_metadata())


def _subtitle(study: str, params: Params | None) -> str:
    from driver._study import load_study
    module = load_study(study) if study else None
    doc = module.spec.doc if module is not None else ""
    t = getattr(params, "get", lambda k, d=None: d)("title", "") if params is not None else ""
    return " — ".join(x for x in (doc, t) if x)


# ----------------------------------------------------------------------------- sweeps, optimisations, synthesis

def _labels(module: Any, names: Iterable[str]) -> dict[str, str]:
    from driver._output import column_label
    return {n: column_label(module, n) for n in names}


def _case_result(deck_path: Path, text: str) -> tuple[Result, Params]:
    """Run a deck text in memory (an optimum, a best case): its Result and Params."""
    from driver._deck import read_deck
    from driver._runner import compute, study_of
    d = read_deck(deck_path, text=text)
    module, params = study_of(d)
    result = compute(module, params)
    result.name, result.study = deck_path.stem, params.group
    return result, params


def _namelist(group: str, values: dict[str, Any]) -> str:
    def lit(v: Any) -> str:
        if isinstance(v, bool):
            return ".true." if v else ".false."
        if isinstance(v, str):
            return "'" + v.replace("'", "''") + "'"
        if isinstance(v, (list, tuple)):
            return ", ".join(lit(x) for x in v)
        if isinstance(v, float):
            return repr(v)
        return str(v)
    return f"&{group}\n" + "".join(f"  {k} = {lit(v)}\n" for k, v in values.items() if v is not None) + "/\n"


def page_for_sweep(deck: Deck, outdir: Path, stem: str, status: int = 0) -> str:
    """The page of a sweep deck, from the files the sweep wrote: the design-space maps of the
    plotted summary columns (kept designs outlined; the best kept design by the first plotted
    column marked where the study says which way is better, its ``sweep_best``, else the first
    kept design), that design's drawing and animation, the summary .out, the deck."""
    import pandas as pd

    from driver import plotting
    from driver._deck import validate
    from driver._runner import study_of
    from driver.sweep._spec import SPEC as SWEEP_SPEC
    outdir = Path(outdir)
    summary = pd.read_parquet(outdir / f"{stem}_summary.parquet")
    text = (outdir / f"{stem}.out").read_text()
    sw = validate(deck.groups["sweep"], SWEEP_SPEC, deck.path)
    base = {g: r for g, r in deck.groups.items() if g != "sweep"}
    from driver._deck import Deck as _Deck
    module, base_params = study_of(_Deck(deck.path, base))
    keys = [k for k in summary.columns if "." in k and k.split(".")[0] == base_params.group]
    numeric = [c for c in summary.columns if c not in keys and c not in ("case", "kept") and
               pd.api.types.is_numeric_dtype(summary[c]) and not pd.api.types.is_bool_dtype(summary[c])]
    wanted = [y for y in (sw.plot_y or []) if y in numeric] or \
        [c for c in module.sweep_plot if c in numeric][:2] or numeric[:1]
    labels = _labels(module, list(summary.columns))
    ok = summary[summary["status"] == "ok"] if "status" in summary else summary
    kept = ok[ok["kept"].astype(bool)] if "kept" in ok else ok
    senses = module.sweep_best
    sections: list[Section] = []
    notes: list[str] = []
    numeric_keys = [k for k in keys if pd.api.types.is_numeric_dtype(summary[k])]
    best = plotting.best_index(ok, wanted[0], senses.get(wanted[0])) if wanted else None
    if best is not None:
        best_text = ("largest " if senses[wanted[0]] == "max" else "smallest ") + labels[wanted[0]].split(" [")[0]
    elif len(kept):
        best, best_text = kept.index[0], "the first kept design"
    else:
        best_text = ""
    maps = []
    try:
        if plotting.is_grid(ok, keys) and not sw.zip:
            figs = plotting.sweep_maps(ok, keys, wanted[:3], labels, senses, stem, sw.summary_rows == "kept")
            maps += [_figure_block(f, f"{labels[y]} over the swept keys") for f, y in zip(figs, wanted)]
        else:   # one key, zipped keys or a kept set that is no grid: the --plot summary (lines, strips)
            fig = plotting.sweep_summary(ok, keys, sw.plot_x, sw.plot_y, stem, labels,
                                         module.sweep_plot)
            maps.append(_figure_block(fig, "the sweep's summary columns against the swept keys"))
    except Exception as exc:
        notes.append(f"the design-space maps could not be drawn: {exc.__class__.__name__}: {exc}")
    sections.append(Section("design-space", "design space", "\n".join(maps) or "<p>No numeric summary column to map.</p>"))
    if best is not None:
        values = dict(deck.groups[base_params.group].values)
        for k in keys:
            v = summary.loc[best, k]
            values[k.split(".", 1)[1]] = v.item() if hasattr(v, "item") else v
        try:
            result, params = _case_result(Path(f"{stem}_case{int(summary.loc[best, 'case'])}.dat"),
                                          _namelist(base_params.group, values))
            body = (f'<p>Case {int(summary.loc[best, "case"])}, {esc(plain(best_text))}: ' + ", ".join(
                f"{esc(k)} = {summary.loc[best, k]:.6g}" for k in numeric_keys) + ".</p>")
            anim = mechanism_animation(params, "anim-best", "The marked design over one crank turn.")
            body += anim or ""
            figs_html, failed = _figures_html(result)
            notes += failed
            body += figs_html + _kv_table(result.summary)
            sections.append(Section("best", "the marked design", body))
        except Exception as exc:
            notes.append(f"the marked design could not be run again: {exc.__class__.__name__}: {exc}")
    sections.append(Section("tables", "sweep summary (.out)", _pre(text)))
    sections.append(Section("summary-table", "summary table", _frame_table(summary)))
    warnings = [f"the sweep finished with status {status} (some cases failed or had bad values; see the summary)"] \
        if status else []
    sections.insert(0, Section("warnings", "warnings", _warnings_html(warnings + notes)))
    sections.append(Section("published", "comparison with the published tables",
                            _comparison_html(None, "A sweep runs a study over many cases; the published tables "
                                                   "belong to single-case decks.")))
    sections.append(Section("deck", "deck", _pre(_deck_text(deck))))
    n_kept = int(summary["kept"].astype(bool).sum()) if "kept" in summary else len(summary)
    sub = f"sweep of &{base_params.group} over {', '.join(keys)}: {len(summary)} rows in the summary, {n_kept} kept"
    return build_page(f"{stem}: sweep", sub, sections, run_metadata())


def _objective(deck: Deck) -> tuple[str, str]:
    """The optimisation's objective text and sense from the deck's &optimize group."""
    values = deck.groups["optimize"].values
    for sense in ("minimize", "maximize", "minimise", "maximise"):
        if values.get(sense):
            return str(values[sense]), "maximize" if sense.startswith("max") else "minimize"
    return "objective", "minimize"


def page_for_optimize(deck: Deck, outdir: Path, stem: str, status: int = 0) -> str:
    """The page of an optimisation deck, from the files it wrote: the convergence plot, the map
    of the designs evaluated over the first two design variables (coloured by the objective,
    infeasible designs grey, the optimum marked), the optimum's drawing and animation, the
    report (.out) and the deck."""
    import pandas as pd

    from driver import plotting
    from driver._deck import Deck as _Deck
    from driver._output import expression_label
    from driver._runner import study_of
    outdir = Path(outdir)
    text = (outdir / f"{stem}.out").read_text()
    history = pd.read_csv(outdir / f"{stem}_history.csv")
    evals = pd.read_parquet(outdir / f"{stem}_evals.parquet")
    module, _ = study_of(_Deck(deck.path, {g: r for g, r in deck.groups.items() if g != "optimize"}))
    obj_text, sense = _objective(deck)
    label = expression_label(module, obj_text)
    sections: list[Section] = []
    notes: list[str] = []
    figs = []
    try:
        fig = plotting.convergence_plot(history, evals, label, sense, title=plotting.plain_text(f"{stem}: convergence"))
        figs.append(_figure_block(fig, "best feasible objective, gap to the final best, constraint violation"))
    except Exception as exc:
        notes.append(f"the convergence plot could not be drawn: {exc.__class__.__name__}: {exc}")
    design = [c for c in evals.columns if "." in c and not c.startswith("summary.")]
    feas = evals[evals["feasible"].astype(bool)]
    if len(design) >= 1 and len(feas):
        opt = feas["objective"].idxmax() if sense == "maximize" else feas["objective"].idxmin()
        frame = evals.assign(kept=evals["feasible"].astype(bool))
        try:
            fig = _evaluated_map(frame, design[:2], label, opt, _labels(module, design),
                                 plotting.plain_text(f"{stem}: designs evaluated"))
            figs.append(_figure_block(fig, "designs evaluated over the design variables"))
        except Exception as exc:
            notes.append(f"the map of designs could not be drawn: {exc.__class__.__name__}: {exc}")
    sections.append(Section("convergence", "convergence and design space", "\n".join(figs)))
    opt_path = outdir / f"{stem}.optimum.dat"
    if opt_path.is_file():
        try:
            result, params = _case_result(opt_path, opt_path.read_text())
            body = mechanism_animation(params, "anim-optimum", "The optimum over one crank turn.") or ""
            f_html, failed = _figures_html(result)
            notes += failed
            body += f_html + _kv_table(result.summary)
            body += f"<details><summary>{esc(opt_path.name)}</summary>{_pre(opt_path.read_text())}</details>"
            sections.append(Section("optimum", "the optimum", body))
        except Exception as exc:
            notes.append(f"the optimum could not be run again: {exc.__class__.__name__}: {exc}")
    sections.append(Section("tables", "report (.out)", _pre(text)))
    sections.append(Section("history", "history", _frame_table(history)))
    warnings = [f"the optimisation finished with status {status} (see the report)"] if status else []
    sections.insert(0, Section("warnings", "warnings", _warnings_html(warnings + notes)))
    sections.append(Section("published", "comparison with the published tables",
                            _comparison_html(None, "An optimisation has no published table of its own; compare "
                                                   "the optimum deck it writes (--compare).")))
    sections.append(Section("deck", "deck", _pre(_deck_text(deck))))
    sub = f"{sense} {obj_text} over {', '.join(design)}; {len(evals)} designs evaluated"
    return build_page(f"{stem}: optimisation", sub, sections, run_metadata())


def _evaluated_map(frame: pd.DataFrame, design: Sequence[str], objective: str, opt: Any,
                   labels: dict[str, str], title: str) -> Any:
    """The designs an optimiser evaluated: feasible ones coloured by the objective, infeasible
    grey, the optimum starred (a scatter: an optimiser's designs are not on a grid)."""
    from driver import plotting
    with plotting.style():
        fig, (ax,) = plotting.new_figure(1, 1, figsize=(6.4, 4.4))
        feas = frame[frame["kept"]]
        bad = frame[~frame["kept"]]
        x = design[0]
        y = design[1] if len(design) > 1 else "objective"
        ax.plot(bad[x], bad[y], "x", ms=3, color="0.6", label="infeasible designs", rasterized=len(bad) > 2000)
        sc = ax.scatter(feas[x], feas[y] if y != "objective" else feas["objective"], c=feas["objective"], s=10,
                        cmap="viridis", label="feasible designs", rasterized=len(feas) > 2000)
        ax.plot([frame.loc[opt, x]], [frame.loc[opt, y]], "*", ms=16, color="C3", mec="k", label="optimum")
        cb = fig.colorbar(sc, ax=ax)
        cb.set_label(plotting.wrap(objective, 40))
        plotting.plain_numbers(cb.ax)
        ax.set_xlabel(labels.get(x, x))
        ax.set_ylabel(labels.get(y, objective) if y != "objective" else objective)
        plotting.plain_numbers(ax)
        ax.legend(loc="best")
        ax.set_title(title)
    return fig


def page_for_synthesis(deck: Deck, outdir: Path, stem: str, status: int = 0) -> str:
    """The page of a synthesis deck, from the files it wrote: the synthesised linkage's
    animation and figures (run again from ``<stem>.linkage.dat``), the report and the deck."""
    outdir = Path(outdir)
    text = (outdir / f"{stem}.out").read_text() if (outdir / f"{stem}.out").is_file() else ""
    sections: list[Section] = []
    notes: list[str] = []
    for png in sorted(outdir.glob(f"{stem}_*.svg")):
        notes.append(f"see also {png.name}")
    link = outdir / f"{stem}.linkage.dat"
    if link.is_file():
        try:
            result, params = _case_result(link, link.read_text())
            body = mechanism_animation(params, "anim-synth", "The synthesised linkage over one crank turn.") or ""
            f_html, failed = _figures_html(result)
            notes += failed
            body += f_html + _kv_table(result.summary)
            body += f"<details><summary>{esc(link.name)}</summary>{_pre(link.read_text())}</details>"
            sections.append(Section("linkage", "the synthesised linkage", body))
        except Exception as exc:
            notes.append(f"the synthesised linkage could not be run again: {exc.__class__.__name__}: {exc}")
    sections.append(Section("tables", "report (.out)", _pre(text)))
    warnings = [f"the synthesis finished with status {status} (see the report)"] if status else []
    sections.insert(0, Section("warnings", "warnings", _warnings_html(warnings + notes)))
    sections.append(Section("deck", "deck", _pre(_deck_text(deck))))
    task = deck.groups["synthesis"].values.get("task", "")
    return build_page(f"{stem}: synthesis", f"four-bar synthesis ({task})", sections, run_metadata())


def write_report(path: Path, page: str) -> Path:
    """Write the page atomically as ``path`` (``<stem>.html``)."""
    from driver._atomic import write_text
    return write_text(Path(path), page)
