"""&robust_example: Taylor's (1996) robust-design example, section 2.3 of [Ma'arif 2006].

Three estimates of the target t_x that minimises the spread of Y = b0 + b1 X + b2 X^2 when X
varies about t_x with standard deviation sigma_x:

* eq. (2.2), the exact tolerance analysis of the known quadratic (2.1);
* dual response (2.3.1): mean and sample std per target (Table 2.2), a quadratic through the
  means (2.7) and through ln(std) (2.8), t_min = -b1/(2 b2) (2.9);
* Taguchi inner/outer array (2.3.2): row means of Table 2.3 arranged by target and noise offset
  (Table 2.4), their mean and sample std per target (Table 2.5), quadratics (2.11)/(2.12),
  t_min (2.13);
* tolerance analysis of the fitted mean (2.3.3): (2.14), t_min (2.15).

``mode = 'report'`` fits (2.8) to the std rounded to 7 dp and (2.11) to the means rounded to 4 dp,
as printed (this reproduces the printed coefficients); ``mode = 'exact'`` uses unrounded values.
The printed results that do not reproduce, eq. (2.12) and the last digit of two Table 2.5 std
values, are compared with the deck's ``printed_*`` values and flagged, not forced.

This is statistics, not mechanism physics: it is plain numpy (no Fortran kernel).
"""
from __future__ import annotations

import math
from decimal import Decimal
from typing import Any

import numpy as np
import pandas as pd

from driver.deck import GroupSpec, Key, Params, non_empty, positive
from driver.export import with_units
from driver.limits import Estimate
from driver.runner import keyword_run
from driver.study import Figure, Result
from driver.table import Column, render_table

__all__ = ["SPEC", "run", "quadratic_fit", "analyse", "MODE_REASONS", "NOT_REPRODUCIBLE"]

#: why mode = 'report' and mode = 'exact' differ, by result item
MODE_REASONS = {
    "eq28": "report fits ln of the std rounded to 7 dp (as printed in Table 2.2)",
    "eq211": "report fits the means rounded to 4 dp (as printed in Table 2.5)",
    "eq212": "report fits ln of the std rounded to 7 dp (as printed in Table 2.5)",
    "eq29": "follows from the fit (2.8)",
    "eq213": "follows from the fit (2.12)",
}

#: printed results of section 2.3 that the printed data do not give, (item, index) -> why
NOT_REPRODUCIBLE = {
    **{("eq212", i): "(2.12) printed coefficients are corrupt: the fit to ln(std) of Table 2.5 gives 29.3118, "
                     "-4.65146, 0.155077; the printed ones give sigma_Y(10) = 0.0004 instead of 0.18 and "
                     "t_min = 15.026 (a transcription error)" for i in range(3)},
    ("std25", 1): "last printed digit: the sample std of the Table 2.4 row is 0.00381881 (prints 0.0038188)",
    ("std25", 2): "last printed digit: the sample std of the Table 2.4 row is 0.18513509 (prints 0.1851351)",
}


def _three(v: Any) -> str | None:
    return None if len(v) == 3 else f"needs three values (b0, b1, b2), got {len(v)}"


def _cross_check(p: Params) -> None:
    nt = len(p.dual_targets)
    if nt < 3:
        raise p.error("dual_targets", f"a quadratic needs at least 3 targets, got {nt}")
    for key in ("dual_targets", "taguchi_targets"):
        distinct = sorted(set(p[key]))
        if len(p[key]) >= 3 and len(distinct) < 3:
            raise p.error(key, f"a quadratic needs at least 3 distinct targets, got {len(distinct)} "
                               f"({', '.join(f'{v:g}' for v in distinct)}): the fit would be singular")
    if len(p.dual_y) % nt or len(p.dual_y) // nt < 2:
        raise p.error("dual_y", f"{len(p.dual_y)} values do not split into {nt} targets of at least 2 "
                                "replicates each (values are listed target by target)")
    nt2, no = len(p.taguchi_targets), len(p.taguchi_offsets)
    if nt2 < 3:
        raise p.error("taguchi_targets", f"a quadratic needs at least 3 targets, got {nt2}")
    if no < 2:
        raise p.error("taguchi_offsets", f"needs at least 2 noise offsets, got {no}")
    if len(p.taguchi_y) % (nt2 * no):
        raise p.error("taguchi_y", f"{len(p.taguchi_y)} values do not split into {nt2} targets x {no} "
                                   "offsets with equal replicates (listed target by target, offset by offset)")
    for key in ("printed_eq212", "printed_eq28", "printed_eq211"):
        if p[key] is not None and len(p[key]) != 3:
            raise p.error(key, f"needs three coefficients (b0, b1, b2), got {len(p[key])}")
    if p.printed_table25_std is not None and len(p.printed_table25_std) != nt2:
        raise p.error("printed_table25_std", f"needs one std per Taguchi target ({nt2}), got "
                                             f"{len(p.printed_table25_std)}")
    if p.true_coeffs[2] == 0.0:
        raise p.error("true_coeffs", "b2 must not be zero: a straight line has no robust target")


SPEC = GroupSpec(
    name="robust_example",
    doc="Taylor (1996) robust-design example, report section 2.3 (dual response, Taguchi, tolerance analysis)",
    check=_cross_check,
    keys={
        "title": Key("str", default=""),
        "mode": Key("str", default="exact", choices=("exact", "report"),
                    doc="'report' fits the printed (rounded) std and means, as the report did"),
        "true_coeffs": Key("floats", default=[-6.0, 1.2, -0.04], check=_three,
                           doc="b0, b1, b2 of the known relation (2.1) Y = b0 + b1 X + b2 X^2"),
        "sigma_x": Key("float", default=0.5, check=positive, doc="standard deviation of X about its target"),
        "dual_targets": Key("floats", required=True, check=non_empty, doc="targets of Table 2.1"),
        "dual_y": Key("floats", required=True, check=non_empty,
                      doc="Table 2.1 observations, target by target (equal replicates)"),
        "taguchi_targets": Key("floats", required=True, check=non_empty, doc="inner-array targets (Table 2.4)"),
        "taguchi_offsets": Key("floats", required=True, check=non_empty, doc="outer-array noise offsets of X"),
        "taguchi_y": Key("floats", required=True, check=non_empty,
                         doc="Table 2.3 observations, by target, then offset (equal replicates)"),
        "printed_eq28": Key("floats", doc="printed (2.8) coefficients, compared with the fit"),
        "printed_eq211": Key("floats", doc="printed (2.11) coefficients, compared with the fit"),
        "printed_eq212": Key("floats", doc="printed (2.12) coefficients, compared with the fit"),
        "printed_table25_std": Key("floats", doc="printed Table 2.5 std, compared with the computed ones"),
    },
)


#: largest condition number of the normal equations X'X accepted for a quadratic fit
MAX_COND = 1e12


class FitError(ValueError):
    """The targets do not determine a quadratic (singular or ill-conditioned normal equations)."""


def quadratic_fit(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Least-squares quadratic b0 + b1 t + b2 t^2 through (t, y): B = (X'X)^-1 X'Y (eq. 2.4).

    Raises FitError when X'X is singular or its condition number exceeds MAX_COND (targets
    too few or too close together for the digits of a double)."""
    X = np.vander(np.asarray(t, float), 3, increasing=True)
    A = X.T @ X
    cond = np.linalg.cond(A)
    if not cond < MAX_COND:
        raise FitError(f"the normal equations of the quadratic fit are "
                       f"{'singular' if not np.isfinite(cond) else f'ill-conditioned (condition number {cond:.2g})'}: "
                       "the targets do not determine a quadratic")
    return np.linalg.solve(A, X.T @ np.asarray(y, float))


def _tmin(b: np.ndarray) -> float:
    """-b1 / (2 b2): stationary point of a quadratic (eqs 2.9, 2.13, 2.15)."""
    return float(-b[1] / (2.0 * b[2]))


def _flat(b: np.ndarray, t: np.ndarray) -> bool:
    """b2 is zero to the fit's rounding: its term is below 1e-9 of the fitted values' size over
    the targets' span."""
    t = np.asarray(t, float)
    span = float(t.max() - t.min())
    size = float(np.max(np.abs(b[0] + b[1] * t + b[2] * t * t))) + abs(b[1]) * span
    return abs(b[2]) * span * span <= 1e-9 * max(size, 1e-300)


def stationary(b: np.ndarray, t: np.ndarray, need_minimum: bool) -> tuple[float | None, str]:
    """t_min of a fitted quadratic, or None with the reason in words.

    ``need_minimum``: the quadratic itself is minimised (ln sigma fits 2.8/2.12), so b2 must be
    positive; otherwise (tolerance analyses 2.2/2.14/2.15) only b2 != 0 is needed, as
    sigma_Y^2 = (b1 + 2 b2 t)^2 sigma_x^2 + 2 b2^2 sigma_x^4 is least at -b1/(2 b2) either way.
    """
    if _flat(b, t):
        return None, (f"no t_min: the fitted quadratic is flat (b2 = {b[2]:.3g} is rounding noise), "
                      "the data show no curvature")
    tm = _tmin(b)
    if need_minimum and b[2] < 0:
        return None, (f"no t_min: b2 = {b[2]:.6g} < 0, the fitted quadratic has a maximum at t = {tm:.3f}; "
                      "the data show no robust target inside their range")
    return tm, ""


def _tmin_text(name: str, value: float | None, why: str) -> str:
    return f"  {name} t_min = {value:.3f}" if value is not None else f"  {name} {why}"


def _r(x: np.ndarray, d: int) -> np.ndarray:
    return np.array([float(Decimal(float(v)).quantize(Decimal(1).scaleb(-d), rounding="ROUND_HALF_UP"))
                     for v in np.atleast_1d(x)])


def analyse(p: Params, report: bool) -> dict[str, Any]:
    """All section-2.3 results for one mode (see the module docstring)."""
    b = np.array(p.true_coeffs, float)
    sx = p.sigma_x
    out: dict[str, Any] = {"eq22_slope": (b[1], 2 * b[2]), "eq22_quartic": 2 * b[2] ** 2, "eq22_tmin": _tmin(b)}
    t = np.array(p.dual_targets, float)
    y = np.array(p.dual_y, float).reshape(t.size, -1)
    mean, std = y.mean(1), y.std(1, ddof=1)
    if np.any(std <= 0):
        raise p.error("dual_y", "a target's observations are all equal: ln(std) is undefined")
    out.update(t22=t, mean22=mean, std22=std)
    try:
        out["eq27"] = quadratic_fit(t, mean)
        out["eq28"] = quadratic_fit(t, np.log(_r(std, 7) if report else std))
    except FitError as exc:
        raise p.error("dual_targets", str(exc)) from None
    out["eq29"], out["eq29_why"] = stationary(out["eq28"], t, need_minimum=True)
    tt, off = np.array(p.taguchi_targets, float), np.array(p.taguchi_offsets, float)
    yt = np.array(p.taguchi_y, float).reshape(tt.size, off.size, -1)
    t24 = yt.mean(2)
    out.update(t24_targets=tt, t24_offsets=off, t24=t24, levels=(tt[:, None] + off[None, :]))
    m25, s25 = t24.mean(1), t24.std(1, ddof=1)
    if np.any(s25 <= 0):
        raise p.error("taguchi_y", "a target's row means are all equal: ln(std) is undefined")
    out.update(mean25=m25, std25=s25)
    try:
        out["eq211"] = quadratic_fit(tt, _r(m25, 4) if report else m25)
        out["eq212"] = quadratic_fit(tt, np.log(_r(s25, 7) if report else s25))
    except FitError as exc:
        raise p.error("taguchi_targets", str(exc)) from None
    out["eq213"], out["eq213_why"] = stationary(out["eq212"], tt, need_minimum=True)
    b27 = out["eq27"]
    if report:  # (2.14) is written from the printed 6-significant-digit coefficients of (2.7)
        b27 = np.array([float(f"{v:.6g}") for v in b27])
    out["eq214_slope"] = (b27[1], 2 * b27[2])
    out["eq214_quartic"] = 2 * b27[2] ** 2
    out["eq215"], out["eq215_why"] = stationary(b27, t, need_minimum=False)
    out["sigma_at"] = lambda tx, bb=b27: math.sqrt((bb[1] + 2 * bb[2] * tx) ** 2 * sx ** 2 + 2 * bb[2] ** 2 * sx ** 4)
    return out


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
        exp = -decimals if decimals is not None else Decimal(repr(float(a))).as_tuple().exponent
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


def estimate(params: Params) -> Estimate:
    """Memory and work from the keys alone (driver.limits): least-squares fits of a few dozen
    numbers; the lists are bounded by the deck reader (10 000 values per key)."""
    n = len(params.dual_y) + len(params.taguchi_y) + len(params.taguchi_targets) * len(params.taguchi_offsets)
    return Estimate(1e6 + 1e3 * n, 0.05 + 1e-5 * n, "taguchi_y", "taguchi_y", f"{n} observations")


#: the tidy table is long: ``value`` is the printed quantity named by ``item`` (coefficients of the
#: fitted response models and times in the example's units; see the .out for each)
TIDY_UNITS = {"index": "1", "value": "unit of item"}


@keyword_run
def run(params: Params, progress: bool = False) -> Result:
    """Run one &robust_example deck."""
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
                     f"{r['std25'][0]:.3g}) and t_min = {_tmin(bp):.3f}: a transcription error")
        L.append("")
    if report:
        e = analyse(p, False)
        L += ["Where mode = 'report' and mode = 'exact' differ", "-" * 47]
        for key, why in ((k, MODE_REASONS[k]) for k in ("eq28", "eq211", "eq212")):
            for i in range(3):
                if _g(r[key][i]) != _g(e[key][i]):
                    L.append(f"  {key}[b{i}]  report {_g(r[key][i]):>11}  exact {_g(e[key][i]):>11}  {why}")
        for key in ("eq29", "eq213"):
            a, c = (f"{v:.3f}" if v is not None else "none" for v in (r[key], e[key]))
            if a != c:
                L.append(f"  {key}  report {a}  exact {c}  follows from the fit")
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
    figures = [Figure("fits", lambda: _fits_figure(p, r))]
    summary = {"mode": p.mode, "tmin_true": r["eq22_tmin"], "tmin_dual_response": r["eq29"],
               "tmin_taguchi": r["eq213"], "tmin_tolerance_analysis": r["eq215"], "flagged": len(flags)}
    return Result(text="\n".join(L).rstrip() + "\n", tidy=with_units(pd.DataFrame.from_records(recs), TIDY_UNITS),
                  summary=summary, figures=figures,
                  warnings=[f"printed value differs in its last digit: {f}" if "the last digit only" in f
                            else f"printed value does not reproduce: {f}" for f in flags])


def _fits_figure(p: Params, r: dict[str, Any]):
    """The section's results on one page: mean and spread of Y against the target, the three
    estimates of t_min (driver.plotting.robust_design_figure)."""
    from driver import plotting
    b = np.array(p.true_coeffs, float)
    sx = p.sigma_x
    t = np.linspace(min(r["t22"].min(), r["t24_targets"].min()) - 1.0,
                    max(r["t22"].max(), r["t24_targets"].max()) + 1.0, 401)
    exact_sigma = np.sqrt((b[1] + 2 * b[2] * t) ** 2 * sx ** 2 + 2 * b[2] ** 2 * sx ** 4)
    quad = lambda c: c[0] + c[1] * t + c[2] * t * t  # noqa: E731
    means = {"known relation (2.1)": quad(b), "dual response fit (2.7)": quad(r["eq27"]),
             "Taguchi fit (2.11)": quad(r["eq211"])}
    spreads = {"tolerance analysis of (2.1), eq. (2.2)": exact_sigma,
               "dual response fit (2.8)": np.exp(quad(r["eq28"])),
               "Taguchi fit (2.12)": np.exp(quad(r["eq212"])),
               "tolerance analysis of (2.7), eq. (2.14)": np.array([r["sigma_at"](x) for x in t])}
    if p.printed_eq212 is not None:
        spreads["(2.12) as printed (mostly off the scale)"] = np.exp(np.clip(quad(np.array(p.printed_eq212, float)), -700, 700))
    points = {"Table 2.2 (dual response)": (r["t22"], r["mean22"], r["std22"]),
              "Table 2.5 (Taguchi)": (r["t24_targets"], r["mean25"], r["std25"])}
    tmins = {"true (2.2)": r["eq22_tmin"], "dual response (2.9)": r["eq29"], "Taguchi (2.13)": r["eq213"],
             "tolerance analysis (2.15)": r["eq215"]}
    return plotting.robust_design_figure(t, means, spreads, points, tmins, sx,
                                         title=p.title or "Taylor's robust-design example")
