"""The &robust_example keys, their cross-check, and the budget estimate of a run."""
from __future__ import annotations

from typing import Any

from driver._deck import GroupSpec, Key, Params, non_empty, positive
from driver._limits import Estimate
from driver._study import contract_doc

__all__ = ["SPEC", "MODE_REASONS", "estimate"]


#: why mode = 'report' and mode = 'exact' differ, by result item
MODE_REASONS = {
    "eq28": "report fits ln of the std rounded to 7 dp (as printed in Table 2.2)",
    "eq211": "report fits the means rounded to 4 dp (as printed in Table 2.5)",
    "eq212": "report fits ln of the std rounded to 7 dp (as printed in Table 2.5)",
    "eq29": "follows from the fit (2.8)",
    "eq213": "follows from the fit (2.12)",
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


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone, before it allocates.

    Least-squares fits of a few dozen
    numbers; the lists are bounded by the deck reader (10 000 values per key).

    %(estimate)s
    """
    n = len(params.dual_y) + len(params.taguchi_y) + len(params.taguchi_targets) * len(params.taguchi_offsets)
    return Estimate(1e6 + 1e3 * n, 0.05 + 1e-5 * n, "taguchi_y", "taguchi_y", f"{n} observations")
