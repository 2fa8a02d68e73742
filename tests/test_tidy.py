"""Tidy tables a pandas user is happy with: units for every column, CSV and Parquet that read
back alike, loop-closure flags in the four-bar table, the manipulator as one long table."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import driver
from conftest import INPUTS
from driver._export import unit_of, with_units, write_tidy
from driver.manipulator import table_frame

FAST = ["crank5", "crank5_coupler_point", "nongrashof", "ujoint_option1", "manipulator_case2_report",
        "robust_example", "slidercrank_simeon1996"]


@pytest.fixture(scope="module")
def results():
    return {name: driver.run(INPUTS / f"{name}.dat") for name in FAST}


def _read_both(frame: pd.DataFrame, tmp_path, name: str = "t") -> tuple[pd.DataFrame, pd.DataFrame]:
    write_tidy(frame, tmp_path / name, "csv")
    write_tidy(frame, tmp_path / name, "parquet")
    return pd.read_csv(tmp_path / f"{name}.csv"), pd.read_parquet(tmp_path / f"{name}.parquet")


def _assert_same(csv: pd.DataFrame, pq: pd.DataFrame) -> None:
    assert list(csv.columns) == list(pq.columns)
    for c in pq.columns:
        if pd.api.types.is_numeric_dtype(pq[c]) or pd.api.types.is_bool_dtype(pq[c]):
            assert csv[c].dtype == pq[c].dtype, (c, csv[c].dtype, pq[c].dtype)
            np.testing.assert_array_equal(csv[c].to_numpy(), pq[c].to_numpy(), err_msg=c)   # exact round trip
        else:   # text: an empty string reads back from CSV as missing
            assert list(csv[c].fillna("").astype(str)) == list(pq[c].fillna("").astype(str)), c


# ----------------------------------------------------------------------------- units and dtypes

def test_every_tidy_column_has_a_unit(results, tmp_path):
    for name, r in results.items():
        units = r.tidy.attrs.get("units")
        assert units is not None and list(units) == list(r.tidy.columns), name
        missing = [c for c, u in units.items() if u is None]
        assert not missing, f"{name}: no unit for {missing}"
        write_tidy(r.tidy, tmp_path / name, "parquet")
        assert pd.read_parquet(tmp_path / f"{name}.parquet").attrs["units"] == units   # kept in the file
    fb = results["crank5"].tidy.attrs["units"]
    assert (fb["xa"], fb["yb"], fb["theta_deg"], fb["rocker_omega_rad_s"], fb["ab_error"]) == \
        ("length", "length", "deg", "rad/s", "length")
    assert results["crank5_coupler_point"].tidy.attrs["units"]["vxp_per_s"] == "length/s"
    assert unit_of("rocker_alpha_rad_s2") == "rad/s^2" and unit_of("tau1_Nm") == "N m" and unit_of("xa", float) is None


def test_csv_and_parquet_read_back_with_the_same_dtypes(results, tmp_path):
    for name, r in results.items():
        csv, pq = _read_both(r.tidy, tmp_path, name)
        _assert_same(csv, pq)
    csv, _ = _read_both(results["crank5"].tidy, tmp_path)
    assert csv["theta_deg"].dtype == np.float64   # written 0.0, 20.0, ... not 0, 20
    # Lampiran 3: i = 0, epsl = 23
    assert (tmp_path / "t.csv").read_text().splitlines()[1].split(",")[:3] == ["listing", "0.0", "23.0"]


def test_csv_writer_edge_cases(tmp_path):
    n = 70_000   # more than one write batch
    frame = pd.DataFrame({
        "x_m": np.linspace(-3.0, 3.0, n), "whole": np.arange(n, dtype=float) * 1e3, "k": np.arange(n),
        "flag": np.arange(n) % 2 == 0, "word": np.where(np.arange(n) % 3 == 0, 'a,"b"', "plain"),
    })
    frame.loc[5, "x_m"] = np.nan
    frame.loc[7, "whole"] = 1e300
    frame.loc[8, "whole"] = -0.0
    frame.loc[9, "word"] = "two\nlines"
    csv, pq = _read_both(frame, tmp_path)
    _assert_same(csv, pq)
    assert csv.loc[9, "word"] == "two\nlines" and csv.loc[0, "word"] == 'a,"b"'
    # a column mixing types goes through pandas, still readable
    mixed = pd.DataFrame({"v": [1, "a", 2.5]})
    write_tidy(mixed, tmp_path / "m", "csv")
    assert (tmp_path / "m.csv").read_text() == "v\n1\na\n2.5\n"
    empty = pd.DataFrame({"a_m": pd.Series([], dtype=float), "b": pd.Series([], dtype=str)})
    write_tidy(empty, tmp_path / "e", "csv")
    assert (tmp_path / "e.csv").read_text() == "a_m,b\n"
    nulls = pd.DataFrame({"peak_rad_s": [None, None], "case": [1, 2]})
    write_tidy(nulls, tmp_path / "n", "csv")
    assert (tmp_path / "n.csv").read_text() == "peak_rad_s,case\n,1\n,2\n"


def test_with_units_fills_from_names_and_explicit_units():
    f = with_units(pd.DataFrame({"theta_deg": [1.0], "xa": [2.0], "status": ["ok"], "ok": [True]}), {"xa": "length"})
    assert f.attrs["units"] == {"theta_deg": "deg", "xa": "length", "status": "", "ok": ""}


# ----------------------------------------------------------------------------- four-bar loop closure

def test_listing_rows_that_do_not_close_the_loop_are_flagged(results):
    tidy = results["crank5"].tidy
    lst, ex = tidy[tidy["method"] == "listing"], tidy[tidy["method"] == "exact"]
    ab = np.hypot(lst["xb"] - lst["xa"], lst["yb"] - lst["ya"])   # the listing's own positions
    np.testing.assert_allclose(lst["ab_error"], ab - 15.0, atol=1e-12)
    flagged = lst["status"] == "loop_not_closed"
    assert list(lst.loc[flagged, "theta_deg"]) == [200.0, 220.0, 240.0, 260.0, 280.0, 300.0, 320.0, 340.0]
    assert (np.abs(ab[flagged] - 15.0) > 1.0).all() and (np.abs(ab[~flagged] - 15.0) < 1e-4 * 15).all()
    assert 16.1 < ab[flagged].min() and ab[flagged].max() < 20.0   # |AB| 16.2 ... 20.0 instead of 15
    assert (lst.loc[~flagged, "status"] == "ok").all()
    assert (np.abs(ex["ab_error"]) < 1e-12).all() and (ex["status"] == "ok").all()


def test_exact_tidy_keeps_other_statuses_and_blank_cells(results):
    tidy = results["nongrashof"].tidy
    assert {"cannot_assemble"} <= set(tidy["status"])
    assert tidy.loc[tidy["status"] == "cannot_assemble", "ab_error"].isna().all()
    assert "loop_not_closed" not in set(tidy["status"])


# ----------------------------------------------------------------------------- manipulator

def test_manipulator_is_one_long_table_without_empty_cells(results, tmp_path):
    tidy = results["manipulator_case2_report"].tidy
    assert list(tidy.columns) == ["table", "row", "label", "quantity", "value", "unit"]
    assert not tidy.isna().any().any() and not (tidy.astype(str) == "").any().any()
    assert set(tidy["table"]) == {"4.1", "4.2", "4.4", "designs", "4.5", "4.6", "4.7", "4.8", "tolerance"}
    assert set(tidy.loc[tidy["quantity"] == "reach", "value"]) <= {0.0, 1.0}
    units = dict(zip(tidy["quantity"], tidy["unit"]))
    assert (units["tau1_Nm"], units["theta1_deg"], units["ri2"], units["l1_m"]) == ("N m", "deg", "1", "m")
    csv, pq = _read_both(tidy, tmp_path)
    _assert_same(csv, pq)


def test_table_frame_gives_the_printed_shape(results):
    tidy = results["manipulator_case2_report"].tidy
    t48 = table_frame(tidy, "4.8")
    assert len(t48) == 29 and list(t48["row"]) == list(range(1, 30))
    assert list(t48.columns[2:]) == ["l1_m", "l2_m", "m1_kg", "m2_kg", "g_m_s2", "theta1_deg", "theta2_deg",
                                     "tau1_Nm", "tau2_Nm"]
    np.testing.assert_allclose(t48["m1_kg"], 10 * t48["l1_m"], rtol=1e-12)   # m_i = 10 l_i kg
    blank = t48["theta1_deg"].isna()
    assert blank.any() and t48.loc[blank, "tau1_Nm"].isna().all()
    with pytest.raises(KeyError):
        table_frame(tidy, "9.9")
