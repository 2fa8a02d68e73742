"""The comparison of a run with the published record, cell by cell.

:func:`compare` runs a deck (in memory; nothing is written) and puts every published cell that
belongs to the deck's study and values (``published/``, read by :mod:`driver.published`) beside
the value the run computes, as a DataFrame with one row per published cell:

========  ===========================================================================
deck      the deck file
table     the published table, e.g. ``Lampiran 3 (crank 5)``, ``Table 4.8``
row       the published row label (crank angle, row number, design name, item)
column    the published column
printed   the value as printed (text)
computed  the run's value at the printed precision (text; empty when it has none)
status    ``identical`` (same text), ``agrees`` (within half a unit of the last printed
          digit, or the stated tolerance), ``not reproducible`` (a printed value known
          not to follow from the paper's own data and formulas), ``departs`` (the deck
          asks for the correct answer and the published one is wrong, for the reason
          given) or ``differs`` (a reproducible cell that does not agree: a defect)
reason    why a cell is not ``identical``/``agrees``, or why a reproduced printed value is
          wrong anyway (errata)
========  ===========================================================================

:func:`compare_text` renders the per-table agreement lines and every cell that does not agree,
as ``python -m driver --compare DECK...`` prints them.  Each study's comparer lives here (one
function per study group); the reasons come from the study modules where they know them.
"""
from __future__ import annotations

import math
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd

from driver import published
from driver.deck import Params, read_deck
from driver.runner import study_of
from driver.study import Result

__all__ = ["COLUMNS", "OK", "Comparison", "agrees_printed", "compare", "compare_decks", "compare_result", "compare_text",
           "run_comparison", "totals_text"]

COLUMNS = ["deck", "table", "row", "column", "printed", "computed", "status", "reason"]
#: statuses that count as agreement (exit status 0)
OK = ("identical", "agrees", "not reproducible", "departs")


def agrees_printed(computed: float, printed: str) -> bool:
    """|computed - printed| <= half a unit of the printed last digit (+1e-9)."""
    try:
        exp = Decimal(printed.strip()).as_tuple().exponent
    except InvalidOperation:
        return False
    half = 0.5 * 10.0 ** int(exp)  # type: ignore[arg-type]
    return math.isfinite(computed) and abs(float(computed) - float(printed)) <= half + 1e-9


def _decimals(printed: str) -> int:
    exp = Decimal(printed.strip()).as_tuple().exponent
    return max(0, -int(exp))  # type: ignore[arg-type]


def _cell(table: str, row: Any, column: str, printed: str, computed: str, status: str, reason: str = "") -> dict:
    return {"table": table, "row": str(row), "column": column, "printed": printed, "computed": computed,
            "status": status, "reason": reason}


# ----------------------------------------------------------------------------- four-bar

def _fourbar(params: Params, result: Result) -> list[dict]:
    from driver import fourbar
    cells = []
    for path in published.records("fourbar"):
        pub = published.read_listing(path)
        if not published.matches(pub.match, params):
            continue
        angles = np.array(sorted({int(r) for r in pub.cells["row"]}), float)
        correct = fourbar.exact_as_listed(params, angles)
        if params.method == "listing":
            computed = {(int(r[0]), c): v for r in published.listing_rows(result.text)
                        for c, v in zip(published.LISTING_COLUMNS, r)}
        else:
            computed = correct
        for rec in pub.cells.itertuples():
            key = (int(rec.row), rec.column)
            got = computed.get(key)
            wrong = correct.get(key) != rec.printed   # the published cell is not the correct answer
            if 180 < key[0] < 360:
                why = fourbar.LISTING_DEFECT
            else:
                why = fourbar.LISTING_PRECISION
            if got is None:
                cells.append(_cell(pub.name, rec.row, rec.column, rec.printed, "", "departs",
                                   "the deck's crank angles (start_deg, step_deg) do not include this published row"))
            elif got == rec.printed:
                cells.append(_cell(pub.name, rec.row, rec.column, rec.printed, got, "identical",
                                   f"erratum: correct value {correct.get(key)}; {why}" if wrong else ""))
            elif params.method == "exact" and not (why == fourbar.LISTING_PRECISION
                                                   and not _one_digit_apart(got, rec.printed, rec.column)):
                cells.append(_cell(pub.name, rec.row, rec.column, rec.printed, got, "departs", why))
            else:
                cells.append(_cell(pub.name, rec.row, rec.column, rec.printed, got, "differs", ""))
    return cells


def _one_digit_apart(a: str, b: str, column: str) -> bool:
    """Whether two printed values differ by at most one unit of the printed last digit
    (a whole degree for the truncated angle columns)."""
    try:
        unit = 1.0 if column in ("epsl", "phi", "beta") else 10.0 ** Decimal(b).as_tuple().exponent  # type: ignore
        return abs(float(a) - float(b)) <= unit * (1 + 1e-9)
    except (ValueError, InvalidOperation):
        return False


# ----------------------------------------------------------------------------- printed numbers

def _numeric_cell(table: str, row: str, column: str, printed: str, value: float | None,
                  flagged: str | None, departs: str | None) -> dict:
    """One printed number against a computed one (None/NaN: the run leaves the cell blank).

    ``flagged``: why the printed value is known not to be reproducible; ``departs``: why the
    deck's correct answer differs (None when the deck reproduces the published conventions).
    """
    blank = value is None or not np.isfinite(value)
    if printed == "":
        comp = "" if blank else f"{value:g}"
        return _cell(table, row, column, "", comp, "identical" if blank else "differs",
                     "" if blank else "the report leaves this cell blank (target out of reach)")
    if blank:
        return _cell(table, row, column, printed, "", "not reproducible" if flagged else
                     ("departs" if departs else "differs"), flagged or departs or "the run leaves this cell blank")
    comp = f"{value:.{_decimals(printed)}f}"
    if comp.startswith("-") and float(comp) == 0.0:
        comp = comp[1:]
    if agrees_printed(value, printed):
        return _cell(table, row, column, printed, comp, "identical" if comp == printed else "agrees")
    if flagged:
        return _cell(table, row, column, printed, comp, "not reproducible", flagged)
    if departs:
        return _cell(table, row, column, printed, comp, "departs", departs)
    return _cell(table, row, column, printed, comp, "differs", "")


def _manipulator(params: Params, result: Result) -> list[dict]:
    from driver import manipulator as m
    exact = params.mode == "exact"

    def text_values() -> dict[str, float | None]:
        s = result.summary
        out = {"r_squared": s["r_m"] ** 2, "R_squared": s["R_m"] ** 2, "crob_radius": s["crob_radius_m"],
               "crob_c_sweep": s["crob_radius_m"] ** 2,
               "dexterity_l1": s["dexterity_l1_m"], "dexterity_l2": s["dexterity_l2_m"],
               "manipulability_l1": s["manipulability_l1_m"], "manipulability_l2": s["manipulability_l2_m"],
               "manipulability_l1_t44": None,
               "min_total_torque": s.get("sweep_min_tau_sum_signed_Nm"), "min_total_l1": s.get("sweep_min_l1_m"),
               "min_total_l2": s.get("sweep_min_l2_m")}
        t44 = m.table_frame(result.tidy, "4.4")
        if len(t44) > 1:
            out["manipulability_l1_t44"] = float(t44["l1_m"].iloc[1])
        return out

    cells = []
    for path in published.records("manipulator"):
        pub = published.read_blocks(path)
        if not published.matches(pub.match, params):
            continue
        tidy, values = result.tidy, text_values()
        for rec in pub.cells.itertuples():
            table = str(rec.table)
            if table == "Text values":
                value = values.get(str(rec.row))
                why_exact = m.TEXT_REASONS.get(str(rec.row), "follows from the cells above") if exact else None
                cells.append(_numeric_cell(table, rec.row, "value", rec.printed, value, None, why_exact))
                continue
            number = table.split()[-1]
            key_t = "4.1" if number == "4.3" else number
            rows = m.table_frame(tidy, key_t)
            label = str(rec.row)
            if label.endswith("."):
                k = int(label[:-1]) - 1
            else:
                k = next((i for i, v in enumerate(rows["label"]) if v == label), -1)
            value = None
            if 0 <= k < len(rows):
                name = m.TIDY_NAMES.get(rec.column, rec.column)
                v = rows[name].iloc[k] if name in rows else None   # a blank printed cell has no tidy row
                value = None if v is None else float(v)
            flagged = m.NOT_REPRODUCIBLE.get((key_t, label, rec.column, rec.printed))
            departs = m.REASONS.get((key_t, rec.column), "follows from the cells above") if exact else None
            cells.append(_numeric_cell(table, label, rec.column, rec.printed, value, flagged, departs))
    return cells


def _robust_example(params: Params, result: Result) -> list[dict]:
    from driver import robust_example as rx
    tidy = result.tidy
    values = {(str(r.item), int(r.index)): float(r.value) for r in tidy.itertuples()}
    exact = params.mode == "exact"
    cells = []
    for path in published.records("robust_example"):
        pub = published.read_blocks(path)
        for rec in pub.cells.itertuples():
            item, index = str(rec.row).rstrip("]").split("[")
            key = (item, int(index))
            departs = rx.MODE_REASONS.get(item, "follows from the unrounded fits") if exact else None
            cells.append(_numeric_cell(f"Section 2.3 {rec.note}", rec.row, "value", rec.printed, values.get(key),
                                       rx.NOT_REPRODUCIBLE.get(key), departs))
    return cells


def _ujoint(params: Params, result: Result) -> list[dict]:
    from driver import ujoint as u
    cells = []
    for path in published.records("ujoint"):
        pub = published.read_blocks(path)
        if not published.matches(pub.match, params):
            continue
        t, s = result.tidy, result.summary
        trial = t[t["design"] == "trial"]
        printed_design = t[t["design"] == "paper printed"]
        option = pub.match.get("option", "?")
        for rec in pub.cells.itertuples():
            q, table = str(rec.row), f"SSO option {option}"
            if q.startswith("trial_band"):
                value = float(trial["omega_out_rpm"].min() if q.endswith("min") else trial["omega_out_rpm"].max())
                comp = f"{value:.2f}"
                if abs(value - float(rec.printed)) <= u.BAND_TOL:   # the figure's reading precision
                    cells.append(_cell(table, q, "rpm", rec.printed, comp, "agrees"))
                elif option == "1":
                    cells.append(_cell(table, q, "rpm", rec.printed, comp, "not reproducible",
                                       u.NOT_REPRODUCIBLE["option1_band"]))
                else:
                    cells.append(_cell(table, q, "rpm", rec.printed, comp, "differs", ""))
            elif q.startswith("x_"):
                name = q[2:]
                v = s.get(f"{name}_deg")
                comp = "" if v is None else f"{v:.4f}"
                why = u.NOT_REPRODUCIBLE["phi_3" if v is None and name == "phi_3" else "x"]
                cells.append(_cell(table, q, "deg", rec.printed, comp, "not reproducible", why))
            elif q == "U":
                comp = ""
                if len(printed_design):
                    comp = f"{((printed_design['ratio'] - 1.0) ** 2).mean() * params.rpm ** 2:.4f}"
                cells.append(_cell(table, q, "", rec.printed, comp, "not reproducible", u.NOT_REPRODUCIBLE["U"]))
            else:
                cells.append(_cell(table, q, "", rec.printed, "", "not reproducible", u.NOT_REPRODUCIBLE[q]))
    return cells


#: relative tolerance of the Simeon (1996) comparison: the tool's linear KED model against the
#: reference's nonlinear modal model (docs/slidercrank.md)
SIMEON_REL_TOL = 5e-3


def _slidercrank(params: Params, result: Result) -> list[dict]:
    from driver import slidercrank as sc
    cells = []
    for path in published.records("slidercrank"):
        pub = published.read_blocks(path)
        if not published.matches(pub.match, params):
            continue
        if "benchmark" in pub.match:       # the Simeon (1996) reference solution, from the run's Table 4
            printed_rows = {}
            for line in result.text.splitlines():
                for sym in ("q1", "q4", "x3", "phi2"):
                    if f"({sym})" in line:
                        printed_rows[sym] = float(line.split()[-3])
            ref = pub.cells[pub.cells["table"].str.startswith("Reference")]
            table = f"Simeon (1996) at t = {ref[ref['row'] == 't_s']['printed'].iloc[0]} s (within 0.5 %)"
            for rec in ref[ref["row"] != "t_s"].itertuples():
                sym = str(rec.row).split("_")[0]
                value = printed_rows.get(sym)
                if value is None:
                    cells.append(_cell(table, rec.row, "", rec.printed, "", "differs", "the run has no such value"))
                    continue
                rel = (value - float(rec.printed)) / abs(float(rec.printed))
                comp = f"{value:.9e}" if abs(value) < 1e-3 else f"{value:.7f}"
                cells.append(_cell(table, rec.row, "value", rec.printed, comp,
                                   "agrees" if abs(rel) <= SIMEON_REL_TOL else "differs",
                                   f"relative difference {100 * rel:+.3f} % (tolerance {100 * SIMEON_REL_TOL:g} %)"))
            continue
        material = params["material"]
        if material not in sc.MATERIALS:
            continue                        # a custom rod: the paper's tables do not apply
        mat = dict(sc.MATERIALS[material], length=params.rod_length)
        used = {"length_m": mat["length"], "area_m2": mat["area"], "second_moment_m4": mat["second_moment"],
                "density_kg_m3": mat["density"], "youngs_modulus_pa": mat["youngs_modulus"],
                "slider_mass_kg": params.slider_mass,
                "bearing_masses_kg": params.bearing_mass_crank + params.bearing_mass_slider,
                "crank_radius_m": params.crank_radius}
        for rec in pub.cells.itertuples():
            if rec.table == "Table 1a" and rec.row != material:
                continue
            key = rec.column if rec.table == "Table 1a" else str(rec.row)
            value = float(used[key])
            same = abs(value - float(rec.printed)) <= 1e-12 * abs(float(rec.printed))
            cells.append(_cell(str(rec.table), rec.row, rec.column if rec.table == "Table 1a" else "value",
                               rec.printed, f"{value:g}", "identical" if same else "departs",
                               "" if same else "the deck sets another value than the paper"))
    return cells


# ----------------------------------------------------------------------------- driver

_COMPARERS: dict[str, Callable[[Params, Result], list[dict]]] = {
    "fourbar": _fourbar,
    "manipulator": _manipulator,
    "robust_example": _robust_example,
    "ujoint": _ujoint,
    "slidercrank": _slidercrank,
}


class _LazyResult:
    """The deck's :class:`Result`, computed on first use (a comparison of inputs needs no run)."""

    def __init__(self, run: Callable[[], Result]):
        self._run, self._result = run, None

    def __getattr__(self, name: str) -> Any:
        if self._result is None:
            self._result = self._run()
        return getattr(self._result, name)


class Comparison:
    """The comparison of one deck: ``frame`` (one row per published cell) and the run's result."""

    def __init__(self, deck: Path, group: str, frame: pd.DataFrame, params: Params | None, note: str = ""):
        self.deck, self.group, self.frame, self.params, self.note = deck, group, frame, params, note

    @property
    def variant(self) -> str:
        """The deck's mode or method (``mode = 'report'``), or '' for a study without one."""
        for key in ("mode", "method"):
            if self.params is not None and key in self.params:
                return f"{key} = '{self.params[key]}'"
        return ""

    @property
    def ok(self) -> bool:
        """Every reproducible cell agrees (no ``differs``)."""
        return not (self.frame["status"] == "differs").any()


def run_comparison(deck: str | Path) -> Comparison:
    """Run ``deck`` in memory and compare it with its published tables (DeckError for bad input)."""
    path = Path(deck)
    d = read_deck(path)
    from driver.runner import CONTROL_GROUPS
    for control in CONTROL_GROUPS:
        if control in d.groups:
            frame = pd.DataFrame(columns=COLUMNS)
            return Comparison(path, control, frame, None,
                              note=f"a &{control} deck runs the study over many cases or designs; the published tables "
                                   "belong to single-case decks (compare a case deck it writes instead)")
    module, params = study_of(d)
    group = module.name
    comparer = _COMPARERS.get(group)
    rows: list[dict] = []
    if comparer is not None:
        rows = comparer(params, _LazyResult(lambda: module.run(params)))  # type: ignore[arg-type]
    frame = pd.DataFrame.from_records(rows, columns=COLUMNS[1:])
    frame.insert(0, "deck", str(path))
    return Comparison(path, group, frame, params)


def compare_result(deck: str | Path, params: Params, result: Result) -> pd.DataFrame:
    """The comparison of a run already made (``params`` validated, ``result`` computed from
    them) with the published record: the frame of :func:`compare`, without running again."""
    comparer = _COMPARERS.get(params.group)
    rows = comparer(params, result) if comparer is not None else []
    frame = pd.DataFrame.from_records(rows, columns=COLUMNS[1:])
    frame.insert(0, "deck", str(deck))
    return frame


def compare(deck: str | Path) -> pd.DataFrame:
    """The comparison of ``deck`` with the published record: one row per published cell
    (columns :data:`COLUMNS`; empty when no published table belongs to the deck)."""
    return run_comparison(deck).frame


def compare_text(cmp: Comparison) -> list[str]:
    """Terminal lines: one agreement line per published table, then every cell that is not
    ``identical``/``agrees`` with its printed and computed values and reason."""
    f = cmp.frame
    lines = [f"{cmp.deck}: &{cmp.group}"]
    if cmp.note:
        return lines + [f"  {cmp.note}"]
    if f.empty:
        lines.append("  no published table belongs to this deck (its study or values are not in published/)")
        return lines
    for table, t in f.groupby("table", sort=False):
        lines.append("  " + _table_line(str(table), t))
    odd = f[~f["status"].isin(["identical", "agrees"])]
    if not odd.empty:
        w = max(len(s) for s in odd["table"])
        for (status, reason), g in odd.groupby(["status", "reason"], sort=False):
            verb = {"departs": "depart", "differs": "differ"}.get(status, status) if len(g) > 1 else status
            lines.append(f"  {len(g)} cell{'s' if len(g) > 1 else ''} {verb}" + (f": {reason}" if reason else ""))
            lines.append(f"    {'table':<{w}}  {'row':>5}  {'column':<8} {'printed':>10} {'computed':>10}")
            for r in g.itertuples():
                lines.append(f"    {r.table:<{w}}  {r.row:>5}  {r.column:<8} {r.printed:>10} {r.computed or '-':>10}")
    errata = f[(f["status"].isin(["identical", "agrees"])) & f["reason"].str.startswith("erratum")]
    if not errata.empty:
        lines.append(f"  {len(errata)} of the reproduced printed cells are wrong (errata): a deck asking for the "
                     "correct answer lists them with the reason")
    return lines


def totals_text(comparisons: list[Comparison]) -> list[str]:
    """One total line per study over several decks."""
    lines = []
    by_group: dict[tuple[str, str], list[pd.DataFrame]] = {}
    for c in comparisons:
        if not c.frame.empty:
            by_group.setdefault((c.group, c.variant), []).append(c.frame)
    for (group, variant), frames in by_group.items():
        f = pd.concat(frames, ignore_index=True)
        what = f"&{group}" + (f" {variant}" if variant else "")
        lines.append(f"  {what} ({len(frames)} deck{'s' if len(frames) > 1 else ''}): "
                     + _table_line("", f).lstrip(": "))
    return lines


def compare_decks(decks: list[Path], out=None) -> int:
    """Compare every deck, print the report (``out``: a text stream, default stdout); exit status
    0 when every reproducible cell agrees, 1 when a cell differs or a run failed, 2 for bad input."""
    import sys
    from driver.deck import DeckError
    out = sys.stdout if out is None else out
    if not published.PUBLISHED_DIR.is_dir():
        print(f"error: the published tables are not installed ({published.PUBLISHED_DIR} is missing); "
              "the install is incomplete: reinstall it (pip install --force-reinstall PATH-TO-THE-SOURCE-OR-WHEEL; "
              "in a clone: bash .ci/setup)", file=sys.stderr)
        return 1
    status, done = 0, []
    for deck in decks:
        try:
            c = run_comparison(deck)
        except DeckError as exc:
            print(f"error: {exc}", file=sys.stderr)
            status = max(status, 2)
            continue
        except Exception as exc:  # a run failure: say so plainly
            print(f"error: {deck}: run failed: {exc.__class__.__name__}: {exc}", file=sys.stderr)
            status = max(status, 1)
            continue
        done.append(c)
        print("\n".join(compare_text(c)), file=out)
        if not c.ok:
            status = max(status, 1)
    if len(done) > 1:
        totals = totals_text(done)
        print("Total", file=out)
        print("\n".join(totals) if totals else
              f"  no published cells among these {len(done)} decks (sweep, optimisation and synthesis decks "
              "have none: compare the single-case decks a sweep writes instead)", file=out)
    return status


def _table_line(table: str, t: pd.DataFrame) -> str:
    counts = t["status"].value_counts()
    n = len(t)
    same = int(counts.get("identical", 0))
    ok = same + int(counts.get("agrees", 0))
    nr = int(counts.get("not reproducible", 0))
    reproducible = n - nr
    if same == n:
        text = f"{table}: {n}/{n} cells identical"
    elif reproducible == 0:
        text = f"{table}: no reproducible cells"
    elif ok == reproducible and not nr:
        text = f"{table}: {ok}/{n} cells agree" + (f" ({same} identical)" if same else "")
    else:
        text = f"{table}: {ok}/{reproducible} reproducible cells agree"
        if same and same != ok:
            text += f" ({same} identical)"
    extra = []
    if nr:
        extra.append(f"{nr} not reproducible (flagged)")
    if counts.get("departs", 0):
        nd = int(counts["departs"])
        extra.append(f"{nd} depart{'s' if nd == 1 else ''} from the published values (the deck asks for the correct answer)")
    if counts.get("differs", 0):
        extra.append(f"{int(counts['differs'])} DIFFER")
    return text + ("; " + "; ".join(extra) if extra else "")
