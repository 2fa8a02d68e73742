"""The published record (published/) and the comparison (driver._compare, ``--compare``).

Expected values are the printed tables in published/ and independent facts about them (the
paper's quadrant defect affects exactly the crank angles in (180, 360); the closed loop at
340 deg from the four-bar note), never numbers the comparison produced earlier.
"""
from __future__ import annotations

import difflib
import shutil

import pytest

from conftest import INPUTS, ROOT
from driver import _compare as compare
from driver import _published as published
from driver._cli import main

CRANKS = (2, 3, 4, 5)


# ----------------------------------------------------------------------------- four-bar

@pytest.mark.parametrize("crank", CRANKS)
def test_diff_of_the_committed_output_shows_only_the_added_sections(crank):
    """`diff outputs/crankN.out published/crankN.out`: every line up to the end of the table is
    identical; the one difference is the tool's audit and summary against the transcription note."""
    out = (ROOT / "outputs" / f"crank{crank}.out").read_text().splitlines()
    pub = (published.PUBLISHED_DIR / f"crank{crank}.out").read_text().splitlines()
    end = max(k for k, l in enumerate(pub) if l.split()[:1] == ["360"])
    assert out[:end + 1] == pub[:end + 1]
    hunks = [op for op in difflib.SequenceMatcher(a=out, b=pub, autojunk=False).get_opcodes() if op[0] != "equal"]
    assert len(hunks) == 1 and hunks[0][1] > end and hunks[0][3] > end
    assert "Audit of the listing" in "\n".join(out[hunks[0][1]:hunks[0][2]])
    assert "Published record" in "\n".join(pub[hunks[0][3]:hunks[0][4]])


def test_published_listing_files_have_190_cells_each_and_match_lines():
    paths = published.records("fourbar")
    assert [p.name for p in paths] == [f"crank{c}.out" for c in CRANKS]
    tables = [published.read_listing(p) for p in paths]
    assert [t.name for t in tables] == ["Lampiran 2 (crank 2)", "Lampiran 2 (crank 3)",
                                        "Lampiran 3 (crank 4)", "Lampiran 3 (crank 5)"]
    assert sum(len(t.cells) for t in tables) == 760
    assert [t.match["crank"] for t in tables] == ["2", "3", "4", "5"]


@pytest.mark.parametrize("crank", CRANKS)
def test_listing_decks_reproduce_all_190_cells(crank):
    f = compare.compare(INPUTS / f"crank{crank}.dat")
    assert len(f) == 190
    assert (f["status"] == "identical").all()
    assert list(f.columns) == compare.COLUMNS
    # the reproduced cells that are wrong: only the mirrored rows, and last-digit precision elsewhere
    wrong = f[f["reason"] != ""]
    defect = wrong[wrong["reason"].str.contains("quadrant")]
    assert sorted({int(r) for r in defect["row"]}) == list(range(200, 341, 20))
    assert set(defect["column"]) <= {"epsl", "phi", "xb", "yb", "omr", "oms"}
    # elsewhere only the last printed digit of a speed (single precision), never a position
    rest = wrong[~wrong["reason"].str.contains("quadrant")]
    assert rest["reason"].str.contains("single precision").all() and set(rest["column"]) <= {"omr", "oms"}
    for r in rest.itertuples():
        correct = r.reason.split("correct value ")[1].split(";")[0]
        assert abs(float(correct) - float(r.printed)) == pytest.approx(1e-4)


def test_exact_deck_lists_the_errata_of_rows_200_to_340():
    f = compare.compare(INPUTS / "crank5_exact.dat")
    assert len(f) == 190 and not (f["status"] == "differs").any()
    dep = f[f["status"] == "departs"]
    defect = dep[dep["reason"].str.contains("quadrant")]
    # rows 200-340, the position/velocity columns; xa, ya and the transmission angle beta stay right
    assert sorted({int(r) for r in defect["row"]}) == list(range(200, 341, 20))
    assert set(defect["column"]) == {"epsl", "phi", "xb", "yb", "omr", "oms"}
    assert len(defect) == 48
    assert (f[f["column"].isin(["i", "xa", "ya", "beta"])]["status"] == "identical").all()
    # rows 0-180 are correct in the paper: at most a last-digit difference, explained as precision
    early = dep[dep["row"].astype(int) <= 180]
    assert early.empty
    rest = dep[~dep["reason"].str.contains("quadrant")]
    assert set(rest["row"]) <= {"360"} and rest["reason"].str.contains("single precision").all()
    # the correct values at 340 deg (closed loop, four-bar note): B = (16.1, 8.0), rocker speed -6.3523
    at340 = f[f["row"] == "340"].set_index("column")["computed"]
    assert (at340["xb"], at340["yb"], at340["oms"]) == ("16.1", "8.0", "-6.3523")


def test_crossed_branch_and_other_linkages_have_no_published_table():
    for deck in ("crank5_crossed.dat", "doublecrank.dat"):
        assert compare.compare(INPUTS / deck).empty


# ----------------------------------------------------------------------------- command line

def test_cli_compare_prints_agreement_lines_and_totals(capsys):
    decks = [str(INPUTS / f"crank{c}.dat") for c in CRANKS]
    assert main(["--compare", *decks]) == 0
    out = capsys.readouterr().out
    for name in ("Lampiran 2 (crank 2)", "Lampiran 2 (crank 3)", "Lampiran 3 (crank 4)", "Lampiran 3 (crank 5)"):
        assert f"{name}: 190/190 cells identical" in out
    assert "&fourbar method = 'listing' (4 decks): 760/760 cells identical" in out


def test_cli_compare_exact_deck_prints_the_errata_with_reasons(capsys):
    assert main(["--compare", str(INPUTS / "crank5_exact.dat")]) == 0
    out = capsys.readouterr().out
    assert "48 cells depart: the listing's quadrant test" in out
    line = next(l for l in out.splitlines() if l.split()[-4:-2] == ["340", "oms"])
    assert line.split()[-2:] == ["-4.0829", "-6.3523"]


def test_cli_compare_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["--compare", str(INPUTS / "crank5.dat")]) == 0
    assert list(tmp_path.iterdir()) == []


def test_a_cell_that_does_not_agree_fails(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "published"
    shutil.copytree(published.PUBLISHED_DIR, folder)
    path = folder / "crank5.out"
    text = path.read_text()
    path.write_text(text.replace("  120   18.0   91.0   73.0   -2.5    4.3   11.8    9.0       .8282",
                                 "  120   18.0   91.0   73.0   -2.5    4.3   11.9    9.0       .8282"))
    monkeypatch.setattr(published, "PUBLISHED_DIR", folder)
    f = compare.compare(INPUTS / "crank5.dat")
    bad = f[f["status"] == "differs"]
    assert list(zip(bad["row"], bad["column"], bad["printed"], bad["computed"])) == [("120", "xb", "11.9", "11.8")]
    assert main(["--compare", str(INPUTS / "crank5.dat")]) == 1
    assert "1 cell differs" in capsys.readouterr().out


def test_bad_deck_gives_status_2(write_deck, capsys):
    deck = write_deck("&fourbar crank = 1 /\n")
    assert main(["--compare", str(deck)]) == 2
    assert "fixed_link" in capsys.readouterr().err


# ----------------------------------------------------------------------------- manipulator and section 2.3

# the printed values the report's own data and formulas do not give (docs/manipulator.md):
# case-2 dexterity 5.85/4.16 (Table 4.4), case-1 theta1 = 34.81 (printed in Tables 4.5 and 4.6),
# the (2.12) coefficients and the last digit of two Table 2.5 std values
FLAGGED = {"manipulator_case1_report.dat": {("Table 4.5", "1.", "theta1"), ("Table 4.6", "1.", "theta1")},
           "manipulator_case2_report.dat": {("Table 4.4", "Dexterity", "l1opt"), ("Table 4.4", "Dexterity", "l2opt")},
           "robust_example.dat": {("Section 2.3 (2.12)", f"eq212[{i}]", "value") for i in range(3)}
           | {("Section 2.3 Table 2.5", "std25[1]", "value"), ("Section 2.3 Table 2.5", "std25[2]", "value")}}


@pytest.mark.parametrize("deck", sorted(FLAGGED))
def test_report_decks_reproduce_every_reproducible_cell_and_flag_the_rest(deck):
    f = compare.compare(INPUTS / deck)
    assert not f.empty and not (f["status"] == "differs").any()
    assert not (f["status"] == "departs").any()
    flagged = f[f["status"] == "not reproducible"]
    assert set(zip(flagged["table"], flagged["row"], flagged["column"])) == FLAGGED[deck]
    assert (flagged["reason"] != "").all()
    # a flagged cell really does not reproduce: more than half a printed unit away
    for r in flagged.itertuples():
        assert not compare.agrees_printed(float(r.computed), r.printed)


def test_report_totals_and_table_4_8_blank_rows():
    f2 = compare.compare(INPUTS / "manipulator_case2_report.dat")
    t48 = f2[f2["table"] == "Table 4.8"]
    assert len(t48) == 29 * 9 and (t48["status"] == "identical").all()
    blank = t48[t48["printed"] == ""]
    assert sorted({int(r[:-1]) for r in blank["row"]}) == [1, 2, 3, 4, 5, 6, 7, 8, 29]
    assert (blank["computed"] == "").all()
    f1 = compare.compare(INPUTS / "manipulator_case1_report.dat")
    assert (len(f1), len(f2)) == (62, 311)


def test_exact_decks_list_where_the_correct_answer_departs():
    f = compare.compare(INPUTS / "manipulator_case2_exact.dat")
    assert not (f["status"] == "differs").any()
    dep = f[f["status"] == "departs"]
    theta1 = dep[(dep["table"] == "Table 4.8") & (dep["column"] == "theta1")]
    assert sorted(int(r[:-1]) for r in theta1["row"]) == list(range(9, 29))
    assert theta1["reason"].str.contains("does not reach the target").all()
    t47 = dep[dep["table"] == "Table 4.7"]
    assert set(t47["column"]) >= {"tau1", "tau2"}
    # the reach conditions and C_rob of Table 4.3 do not depend on the report's conventions
    assert (f[f["table"] == "Table 4.3"]["status"] == "identical").all()
    # chapter 5 reverses: the correct minimum of Table 4.8 is another design
    ch5 = f[(f["table"] == "Text values") & (f["row"] == "min_total_l1")]
    assert ch5["status"].tolist() == ["departs"]


def test_cli_totals_over_the_paper_decks(capsys):
    decks = [str(INPUTS / d) for d in ("crank2.dat", "crank3.dat", "crank4.dat", "crank5.dat",
                                        "manipulator_case1_report.dat", "manipulator_case2_report.dat",
                                        "robust_example.dat")]
    assert main(["--compare", *decks]) == 0
    out = capsys.readouterr().out
    assert "&fourbar method = 'listing' (4 decks): 760/760 cells identical" in out
    assert "&manipulator mode = 'report' (2 decks): 369/369 reproducible cells agree; 4 not reproducible" in out
    assert "&robust_example mode = 'report' (1 deck): 37/37 reproducible cells agree; 5 not reproducible" in out


# ----------------------------------------------------------------------------- Hooke joint, slider-crank

def test_ujoint_printed_optima_are_flagged_and_trial_bands_agree():
    """Trial bands of options 2 and 3 agree within the figure's whole-rpm reading; option 1's band,
    every printed optimum, U and iteration count are flagged with a reason (docs/ujoint.md)."""
    total = {}
    for n in (1, 2, 3):
        f = compare.compare(INPUTS / f"ujoint_option{n}.dat")
        assert not (f["status"] == "differs").any()
        bands = f[f["row"].str.startswith("trial_band")]
        want = "not reproducible" if n == 1 else "agrees"
        assert (bands["status"] == want).all()
        rest = f[~f["row"].str.startswith("trial_band")]
        assert (rest["status"] == "not reproducible").all() and (rest["reason"] != "").all()
        assert {"U", "iterations", "evaluations"} <= set(rest["row"])
        total[n] = len(f)
    assert total == {1: 8, 2: 8, 3: 11}


def test_simeon_benchmark_within_half_a_percent():
    f = compare.compare(INPUTS / "slidercrank_simeon1996.dat")
    assert list(f["row"]) == ["q1_m", "q4_m", "x3_m", "phi2_rad"]
    assert (f["status"] == "agrees").all()
    for r in f.itertuples():
        assert abs(float(r.computed) / float(r.printed) - 1) <= 5e-3


def test_slidercrank_decks_use_table_1_and_a_changed_value_departs(write_deck):
    f = compare.compare(INPUTS / "slidercrank_aluminium.dat")
    assert len(f) == 8 and (f["status"] == "identical").all()
    text = (INPUTS / "slidercrank_aluminium.dat").read_text().replace("slider_mass = 0.9", "slider_mass = 1.2")
    f = compare.compare(write_deck(text))
    dep = f[f["status"] == "departs"]
    assert list(zip(dep["row"], dep["printed"], dep["computed"])) == [("slider_mass_kg", "0.9", "1.2")]


def test_every_published_file_is_read_and_has_a_comparer():
    folder = published.PUBLISHED_DIR
    files = sorted(p.name for p in folder.iterdir() if p.suffix in (".out", ".txt"))
    groups = {published.match_line(folder / name)[0] for name in files}
    from driver._study import load_study
    assert all(load_study(g) is not None and load_study(g).published is not None for g in groups)
    assert len(files) == 12


def test_sweep_and_other_multi_case_decks_are_skipped_with_a_note(capsys):
    assert main(["--compare", str(INPUTS / "fourbar_paper_sweep.dat"), str(INPUTS / "crank2.dat")]) == 0
    out = capsys.readouterr().out
    assert "a &sweep deck runs the study over many cases" in out
    assert "Lampiran 2 (crank 2): 190/190 cells identical" in out


def test_listing_deck_on_a_coarser_grid_departs_on_the_rows_it_does_not_print(write_deck):
    text = (INPUTS / "crank5.dat").read_text().replace("step_deg   = 20", "step_deg   = 40")
    f = compare.compare(write_deck(text))
    assert not (f["status"] == "differs").any()
    missing = f[f["status"] == "departs"]
    assert sorted({int(r) for r in missing["row"]}) == list(range(20, 360, 40))
    assert (f[f["row"].astype(int) % 40 == 0]["status"] == "identical").all()


def test_missing_published_folder_is_one_line_not_a_traceback(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(published, "PUBLISHED_DIR", tmp_path / "nowhere")
    assert main(["--compare", str(INPUTS / "crank5.dat")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "published tables are not installed" in err
