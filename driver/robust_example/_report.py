"""A &robust_example deck run: the fits, tables and estimates of section 2.3 as a fixed-format
.out, the printed values compared at their printed digits, the tidy table and the summary."""
from __future__ import annotations

import math
from decimal import Decimal

import numpy as np
import pandas as pd

from driver._deck import Params
from driver._export import with_units
from driver._result import Figure, Result
from driver._runner import study_run
from driver._table import Column, render_table
from driver.robust_example._analysis import analyse, tmin
from driver.robust_example._spec import MODE_REASONS, SPEC

__all__ = ["run", "TIDY_UNITS"]


def _tmin_text(name: str, value: float | None, why: str) -> str:
    return f"  {name} t_min = {value:.3f}" if value is not None else f"  {name} {why}"


def _g(x: float, sig: int = 6) -> str:
    return f"{x:.{sig}g}"


def _poly(b: np.ndarray) -> str:
    return f"{_g(b[0])} {'+' if b[1] >= 0 else '-'} {_g(abs(b[1]))} t {'+' if b[2] >= 0 else '-'} {_g(abs(b[2]))} t^2"


def _compare(name: str, printed: list[float] | None, computed: np.ndarray,
             decimals: int | None = None) -> tuple[list[str], list[str]]:
    """Lines comparing printed with computed values at the printed digits; flags for mismatches.

    The printed digits are those of the deck value, or ``decimals`` for a fixed-decimal column
    (a float cannot keep a printed trailing zero such as 0.1851350).
    """
    if printed is None:
        return [], []
    lines, flags = [], []
    for i, (a, c) in enumerate(zip(printed, computed)):
        if decimals is not None:
            exp = -decimals
        else:
            exponent = Decimal(repr(float(a))).as_tuple().exponent
            assert isinstance(exponent, int)   # a printed number is finite ('n'/'N'/'F': NaN, inf)
            exp = exponent
        unit = 10.0 ** exp
        ok = abs(a - c) <= 0.5 * unit + 1e-12
        # one unit off in the last printed digit: a rounding slip, not a wrong method
        last_digit = not ok and abs(a - c) <= 1.5 * unit + 1e-12
        text = f"{a:.{decimals}f}" if decimals is not None else repr(float(a))
        verdict = "reproduced" if ok else ("LAST DIGIT" if last_digit else "NOT REPRODUCED")
        lines.append(f"  {name}[{i}]  printed {text:>12}  computed {c:.10g}  {verdict}")
        if last_digit:
            rounded = f"{c:.{max(0, -exp)}f}"
            flags.append(f"{name}[{i}]: printed {text}, computed {c:.10g}: the last digit only (the computed "
                         f"value rounds to {rounded}; a rounding slip, not a wrong method)")
        elif not ok:
            rel = abs(a - c) / max(abs(c), 1e-300)
            flags.append(f"{name}[{i}]: printed {text}, computed {c:.10g} (off by {100 * rel:.2g} %)")
    return lines, flags


#: the tidy table is long: ``value`` is the printed quantity named by ``item`` (coefficients of the
#: fitted response models and times in the example's units; see the .out for each)
TIDY_UNITS = {"index": "1", "value": "unit of item"}


@study_run(SPEC)
def run(params: Params, progress: bool = False) -> Result:
    """Estimate the robust target of Taylor's (1996) example three ways ([Ma'arif 2006], 2.3).

    Exact tolerance analysis of the known quadratic, dual response and the Taguchi inner/outer
    array, each giving the target t_x that minimises the spread of Y.  X and Y carry the units
    of the deck's data (the example gives none).
    """
    p = params
    report = p.mode == "report"
    r = analyse(p, report)
    b = np.array(p.true_coeffs, float)
    L = ["Robust design example (Taylor 1996; [Ma'arif 2006], section 2.3)", "=" * 58]
    if p.title:
        L.append(f"case: {p.title}")
    L += [f"deck: {p.path.name}", f"mode: {p.mode}" + ("  (fits use the printed, rounded std and means)" if report
                                                     else "  (fits use unrounded statistics)"),
          f"known relation (2.1): Y = {_poly(b)},  sigma_x = {p.sigma_x:g}", ""]
    s1, s2 = r["eq22_slope"]
    L += ["Tolerance analysis of the known relation (2.2)", "-" * 46,
          f"  sigma_Y(t) = sqrt(({_g(s1)} {'+' if s2 >= 0 else '-'} {_g(abs(s2))} t)^2 sigma_x^2 + "
          f"{_g(r['eq22_quartic'])} sigma_x^4),  true t_min = {_g(r['eq22_tmin'])}", ""]
    cols = [Column("Target", "f", 8, 1), Column("Mean", "f", 12, 7), Column("Std dev", "f", 12, 7)]
    L += ["Table 2.2  Mean and standard deviation (sample std, ddof = 1)", "-" * 61]
    L += render_table(cols, [[a, m, s] for a, m, s in zip(r["t22"], r["mean22"], r["std22"])]) + [""]
    L += ["Dual response fits", "-" * 18, f"  (2.7) mu_Y(t)    = {_poly(r['eq27'])}",
          f"  (2.8) sigma_Y(t) = exp({_poly(r['eq28'])})", _tmin_text("(2.9)", r["eq29"], r["eq29_why"]), ""]
    head = [Column("Target", "f", 8, 1)] + [Column(f"{o:+g}", "f", 9, 4) for o in r["t24_offsets"]]
    L += ["Table 2.4  Means of the Table 2.3 rows (target x noise offset of X)", "-" * 66]
    L += render_table(head, [[t, *row] for t, row in zip(r["t24_targets"], r["t24"])]) + [""]
    L += ["Table 2.5  Mean and standard deviation of Y per target", "-" * 54]
    cols5 = [Column("Target", "f", 8, 1), Column("Mean", "f", 10, 4), Column("Std dev", "f", 12, 7)]
    L += render_table(cols5, [[t, m, s] for t, m, s in zip(r["t24_targets"], r["mean25"], r["std25"])]) + [""]
    L += ["Taguchi fits", "-" * 12, f"  (2.11) mu_Y(t)    = {_poly(r['eq211'])}",
          f"  (2.12) sigma_Y(t) = exp({_poly(r['eq212'])})", _tmin_text("(2.13)", r["eq213"], r["eq213_why"]), ""]
    s1, s2 = r["eq214_slope"]
    L += ["Tolerance analysis of the fitted mean", "-" * 37,
          f"  (2.14) sigma_Y(t) = sqrt(({_g(s1)} {'+' if s2 >= 0 else '-'} {_g(abs(s2))} t)^2 sigma_x^2 + "
          f"{_g(r['eq214_quartic'])} sigma_x^4)",
          _tmin_text("(2.15)", r["eq215"], r["eq215_why"]), ""]
    comp, flags = [], []
    for name, printed, computed, dec in (("(2.8)", p.printed_eq28, r["eq28"], None),
                                         ("(2.11)", p.printed_eq211, r["eq211"], None),
                                         ("(2.12)", p.printed_eq212, r["eq212"], None),
                                         ("Table 2.5 std", p.printed_table25_std, r["std25"], 7)):
        c, f = _compare(name, printed, computed, dec)
        comp += c
        flags += f
    if comp:
        L += ["Printed values compared at their printed digits", "-" * 47] + comp + [""]
    if flags:
        L += ["Flagged: printed results that do not reproduce (not forced)", "-" * 59]
        L += [f"  {f}" for f in flags]
        if p.printed_eq212 is not None:
            bp = np.array(p.printed_eq212)
            log_s10 = float(bp @ [1, 10, 100])
            s10 = f"{math.exp(log_s10):.3g}" if log_s10 < 700 else f"exp({log_s10:.4g})"
            L.append(f"  printed (2.12) would give sigma_Y(10) = {s10} (Table 2.5: "
                     f"{r['std25'][0]:.3g}) and t_min = {tmin(bp):.3f}: a transcription error")
        L.append("")
    if report:
        e = analyse(p, False)
        L += ["Where mode = 'report' and mode = 'exact' differ", "-" * 47]
        for key, why in ((k, MODE_REASONS[k]) for k in ("eq28", "eq211", "eq212")):
            for i in range(3):
                if _g(r[key][i]) != _g(e[key][i]):
                    L.append(f"  {key}[b{i}]  report {_g(r[key][i]):>11}  exact {_g(e[key][i]):>11}  {why}")
        for key in ("eq29", "eq213"):
            as_report, as_exact = (f"{v:.3f}" if v is not None else "none" for v in (r[key], e[key]))
            if as_report != as_exact:
                L.append(f"  {key}  report {as_report}  exact {as_exact}  follows from the fit")
        L.append("")
    recs = []
    for key in ("eq27", "eq28", "eq211", "eq212"):
        for i, v in enumerate(r[key]):
            recs.append({"item": key, "index": i, "value": float(v)})
    for key in ("eq22_tmin", "eq29", "eq213", "eq215", "eq22_quartic", "eq214_quartic"):
        if r[key] is not None:     # a t_min that does not exist has no row (the .out says why)
            recs.append({"item": key, "index": 0, "value": float(r[key])})
    recs.append({"item": "eq22_slope", "index": 0, "value": float(r["eq22_slope"][0])})
    recs.append({"item": "eq22_slope", "index": 1, "value": float(r["eq22_slope"][1])})
    recs.append({"item": "eq214_slope", "index": 0, "value": float(r["eq214_slope"][0])})
    recs.append({"item": "eq214_slope", "index": 1, "value": float(r["eq214_slope"][1])})
    for key in ("mean22", "std22", "mean25", "std25"):
        for i, v in enumerate(r[key]):
            recs.append({"item": key, "index": i, "value": float(v)})
    for i, row in enumerate(r["t24"]):
        for j, v in enumerate(row):
            recs.append({"item": "t24", "index": i * len(row) + j, "value": float(v)})
    figures = [Figure("fits", lambda: _figures().fits_figure(p, r))]
    summary = {"mode": p.mode, "tmin_true": r["eq22_tmin"], "tmin_dual_response": r["eq29"],
               "tmin_taguchi": r["eq213"], "tmin_tolerance_analysis": r["eq215"], "flagged": len(flags)}
    return Result(text="\n".join(L).rstrip() + "\n", tidy=with_units(pd.DataFrame.from_records(recs), TIDY_UNITS),
                  summary=summary, figures=figures,
                  warnings=[f"printed value differs in its last digit: {f}" if "the last digit only" in f
                            else f"printed value does not reproduce: {f}" for f in flags])


def _figures():
    """The study's figure module, imported when a figure is drawn (matplotlib is the optional [plot] extra)."""
    from driver.robust_example import _figures as figures
    return figures
