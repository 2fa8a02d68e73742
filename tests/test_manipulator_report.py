"""Report decks against the printed cells of [Ma'arif 2006], chapter 4 (the cells docs/manipulator.md lists as reproducible).

Printed values are transcribed as text in published/manipulator_case1.txt and _case2.txt (the text
keeps the printed number of decimals; read through driver._published, as the comparison reads
them); a computed value matches when it is within half a unit of the last printed digit (+1e-9),
never through a bare round().
"""
from __future__ import annotations

from decimal import Decimal
from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd

from driver._deck import read_deck
from driver._published import PUBLISHED_DIR, read_blocks
from driver._runner import study_of
from driver.manipulator import table_frame

ROOT = Path(__file__).resolve().parents[1]


def assert_printed(computed: float, printed: str, what: str = "") -> None:
    """|computed - printed| <= half a unit of the printed last digit + 1e-9."""
    exp = Decimal(printed.strip()).as_tuple().exponent
    half = 0.5 * 10.0 ** exp
    assert abs(float(computed) - float(printed)) <= half + 1e-9, \
        f"{what}: computed {computed!r} vs printed {printed} (allowed +-{half:g})"


@cache
def run_deck(name: str):
    module, params = study_of(read_deck(ROOT / "inputs" / name))
    return module.run(params), params


def table(result, key: str) -> pd.DataFrame:
    return table_frame(result.tidy, key)


def _cells(case: str, table: str) -> pd.DataFrame:
    """Printed cells of one table of published/manipulator_case<case>.txt, one row per printed row."""
    c = read_blocks(PUBLISHED_DIR / f"manipulator_case{case}.txt").cells
    c = c[c["table"] == table]
    wide = c.pivot(index="row", columns="column", values="printed")
    order = list(dict.fromkeys(c["row"]))
    return wide.loc[order].reset_index()


# case-1 Table 4.5 theta1 = 34.81 is the report's slip (not reproducible; docs/manipulator.md)
UNSAFE_THETA1 = {("1", 1)}


def csv(name: str) -> pd.DataFrame:
    """The printed values in the shape of the former transcription tables."""
    if name == "scalars.csv":
        frames = []
        for case in ("1", "2"):
            t = _cells(case, "Text values").rename(columns={"row": "quantity", "value": "printed"})
            t.insert(0, "case", case)
            frames.append(t)
        out = pd.concat(frames, ignore_index=True)
        return out[~out["quantity"].str.startswith("min_total")]
    if name == "chapter5.csv":
        t = _cells("2", "Text values").rename(columns={"row": "quantity", "value": "printed"})
        return t[t["quantity"].str.startswith("min_total")].assign(quantity=lambda d: d["quantity"])
    if name == "table_4_1.csv":
        return pd.concat([_cells("1", "Table 4.1").assign(case="1"), _cells("2", "Table 4.3").assign(case="2")],
                         ignore_index=True)
    if name == "table_4_2.csv":
        return _cells("1", "Table 4.2")
    if name in ("table_4_5.csv", "table_4_7.csv"):
        table = "Table 4.5" if name == "table_4_5.csv" else "Table 4.7"
        frames = []
        for case in ("1", "2"):
            t = _cells(case, table)
            t["case"], t["row"] = case, t["row"].str.rstrip(".")
            if table == "Table 4.5":
                t["safe_theta1"] = ["no" if (case, int(r)) in UNSAFE_THETA1 else "yes" for r in t["row"]]
            frames.append(t)
        return pd.concat(frames, ignore_index=True)
    if name == "table_4_8.csv":
        return _cells("2", "Table 4.8")
    raise KeyError(name)


DECK = {"1": "manipulator_case1_report.dat", "2": "manipulator_case2_report.dat"}


def test_scalars_r_R_crob_and_optima():
    for _, row in csv("scalars.csv").iterrows():
        res, _ = run_deck(DECK[row["case"]])
        s = res.summary
        value = {"r_squared": s["r_m"] ** 2, "R_squared": s["R_m"] ** 2, "crob_radius": s["crob_radius_m"],
                 "dexterity_l1": s["dexterity_l1_m"], "dexterity_l2": s["dexterity_l2_m"],
                 "manipulability_l1": s["manipulability_l1_m"], "manipulability_l2": s["manipulability_l2_m"],
                 "manipulability_l1_t44": table(res, "4.4").loc[1, "l1_m"],
                 "crob_c_sweep": s["crob_radius_m"] ** 2}[row["quantity"]]   # 51.49 = 7.176^2 to 2 dp
        assert_printed(value, row["printed"], f"case {row['case']} {row['quantity']}")


def test_table_4_4_printed_two_decimals():
    res, _ = run_deck(DECK["1"])
    t = table(res, "4.4")
    for i, (l1, l2) in enumerate((("5.61", "3.97"), ("4.86", "4.86"))):
        assert_printed(t.loc[i, "l1_m"], l1, "Table 4.4 l1")
        assert_printed(t.loc[i, "l2_m"], l2, "Table 4.4 l2")


def test_tables_4_1_and_4_3():
    for _, row in csv("table_4_1.csv").iterrows():
        t = table(run_deck(DECK[row["case"]])[0], "4.1")
        for col in ("RI2", "n", "a1", "b2", "a2", "b1"):
            key = "ri2" if col == "RI2" else col
            assert_printed(t.loc[0, key], row[col], f"Table 4.1/4.3 {col}")


def test_table_4_2_pairs_on_crob():
    t = table(run_deck(DECK["1"])[0], "4.2")
    ref = csv("table_4_2.csv")
    assert len(t) == len(ref)
    for i, row in ref.iterrows():
        assert_printed(t.loc[i, "l1_m"], row["l1"], f"Table 4.2 row {i + 1} l1")
        assert_printed(t.loc[i, "l2_m"], row["l2"], f"Table 4.2 row {i + 1} l2")
        assert_printed(t.loc[i, "ri2"], row["RI2"], f"Table 4.2 row {i + 1} RI2")


def test_table_4_5_angles_and_masses():
    for _, row in csv("table_4_5.csv").iterrows():
        t = table(run_deck(DECK[row["case"]])[0], "4.5")
        k = int(row["row"]) - 1
        for col, key in (("l1", "l1_m"), ("l2", "l2_m"), ("m1", "m1_kg"), ("m2", "m2_kg"), ("g", "g_m_s2"),
                         ("theta2", "theta2_deg")):
            assert_printed(t.loc[k, key], row[col], f"Table 4.5 case {row['case']} row {k + 1} {col}")
        if row["safe_theta1"] == "yes":
            assert_printed(t.loc[k, "theta1_deg"], row["theta1"], f"Table 4.5 case {row['case']} theta1")
        else:  # 34.81 is the report's slip: the IK gives 35.50 and the .out says so
            assert abs(t.loc[k, "theta1_deg"] - float(row["theta1"])) > 0.5


def test_table_4_7_torques():
    for _, row in csv("table_4_7.csv").iterrows():
        t = table(run_deck(DECK[row["case"]])[0], "4.7")
        k = int(row["row"]) - 1
        for col, key in (("l1", "l1_m"), ("l2", "l2_m"), ("tau1", "tau1_Nm"), ("tau2", "tau2_Nm")):
            assert_printed(t.loc[k, key], row[col], f"Table 4.7 case {row['case']} row {k + 1} {col}")


def test_table_4_8_all_cells_and_blank_rows():
    res, _ = run_deck(DECK["2"])
    t = table(res, "4.8")
    ref = csv("table_4_8.csv")
    assert len(t) == len(ref) == 29
    for i, row in ref.iterrows():
        for col, key in (("l1", "l1_m"), ("l2", "l2_m"), ("m1", "m1_kg"), ("m2", "m2_kg"), ("g", "g_m_s2"),
                         ("theta1", "theta1_deg"), ("theta2", "theta2_deg"), ("tau1", "tau1_Nm"),
                         ("tau2", "tau2_Nm")):
            if row[col] == "":
                assert np.isnan(t.loc[i, key]), f"Table 4.8 row {i + 1} {col} should be blank"
            else:
                assert_printed(t.loc[i, key], row[col], f"Table 4.8 row {i + 1} {col}")
    # blank rows are marked in words, never NaN in the .out
    lines = [l for l in res.text.splitlines() if l.strip().startswith(("1.", "29."))]
    assert any("target out of reach" in l for l in lines)
    assert "nan" not in res.text.lower() and "****" not in res.text


def test_chapter5_claims():
    res, _ = run_deck(DECK["2"])
    ref = {r["quantity"]: r["printed"] for _, r in csv("chapter5.csv").iterrows()}
    assert set(ref) == {"min_total_torque", "min_total_l1", "min_total_l2"}
    s = res.summary
    assert_printed(s["sweep_min_tau_sum_signed_Nm"], ref["min_total_torque"], "min total torque")
    assert_printed(s["sweep_min_l1_m"], ref["min_total_l1"], "l1 at the minimum")
    assert_printed(s["sweep_min_l2_m"], ref["min_total_l2"], "l2 at the minimum")
    assert s["sweep_min_reaches_workspace"] is False   # row 28 violates |l1 - l2| <= sqrt(17)
    for case in ("1", "2"):  # dexterity needs less total torque than manipulability
        s = run_deck(DECK[case])[0].summary
        assert s["dexterity_tau1_Nm"] + s["dexterity_tau2_Nm"] < s["workspace_tau1_Nm"] + s["workspace_tau2_Nm"]


def test_report_out_lists_mode_differences_and_unreproducible_inputs():
    text1 = run_deck(DECK["1"])[0].text
    text2 = run_deck(DECK["2"])[0].text
    assert "Cells where mode = 'report' and mode = 'exact' differ" in text2
    assert "Table 4.8  row 13 theta1" in text2 and "does not reach the target" in text2
    assert "Table 4.5  row  1 theta2" in text1 and "interior angle" in text1
    assert "printed theta1 = 34.81" in text1
    assert "(5.85, 4.16) is not the computed dexterity optimum (5.86, 4.14)" in text2
    assert "printed theta1 = 34.7 " not in text2    # 34.7 matches at its printed 1 dp


def test_figures_draw():
    res, _ = run_deck(DECK["2"])
    for fig in res.figures:
        assert fig.draw() is not None
