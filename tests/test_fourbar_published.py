"""The listing method against the published tables (Lampiran 2-3 of the four-bar paper), cell for cell.

The transcriptions are the files published/crank2.out ... crank5.out (read through
driver._published, the same reader the comparison uses); the .out files are produced by the
CLI exactly as a user runs it.
"""
from __future__ import annotations

import pytest

from conftest import INPUTS
from driver._cli import main
from driver._published import PUBLISHED_DIR, listing_rows

CRANKS = (2, 3, 4, 5)


def published(crank: int) -> list[list[str]]:
    return listing_rows((PUBLISHED_DIR / f"crank{crank}.out").read_text())


def table_rows(out_text: str) -> list[list[str]]:
    """Rows of the listing table: the lines between the column header and the next blank line."""
    return listing_rows(out_text)


def run_deck(deck, tmp_path) -> str:
    assert main([str(deck), "-o", str(tmp_path), "-q"]) == 0
    return (tmp_path / f"{deck.stem}.out").read_text()


@pytest.mark.parametrize("crank", CRANKS)
def test_every_published_cell_is_reproduced(crank, tmp_path):
    rows = table_rows(run_deck(INPUTS / f"crank{crank}.dat", tmp_path))
    pub = published(crank)
    assert len(rows) == len(pub) == 19
    mismatches = [(r[0], j, a, b) for r, p in zip(rows, pub) for j, (a, b) in enumerate(zip(r, p)) if a != b]
    assert all(len(r) == 10 for r in rows)
    assert mismatches == []


def test_760_cells_in_total(tmp_path):
    n = sum(len(r) for c in CRANKS for r in published(c))
    assert n == 760


def test_header_lines_echo_the_deck_in_the_listing_format(tmp_path):
    text = run_deck(INPUTS / "crank5.dat", tmp_path)
    assert "  panjang OA-OB (fixed link):  12.00" in text
    assert "  panjang poros engkol (crank/driver):   5.00" in text
    assert "  kecepatan sudut poros engkol (rad/detik):   5.00" in text


def test_rows_follow_format_25_column_positions(tmp_path):
    """(2x,i3,2x,7(f5.1,2x),3x,2(f7.4,3x)): fields end at fixed columns."""
    rows = run_deck(INPUTS / "crank2.dat", tmp_path).splitlines()
    row = next(l for l in rows if l.startswith("   20 "))
    ends = [5] + [5 + 7 * k for k in range(1, 8)] + [56 + 3 + 7, 56 + 3 + 7 + 3 + 7]
    for e in ends:
        assert row[e - 1] != " " and (e == len(row) or row[e] == " ")


def test_legacy_terminal_input_equals_namelist_deck(tmp_path):
    a = run_deck(INPUTS / "crank5.dat", tmp_path)
    b = run_deck(INPUTS / "crank5_terminal.dat", tmp_path)
    assert table_rows(a) == table_rows(b) == published(5)


def test_audit_flags_exactly_the_mirrored_rows(tmp_path, capsys):
    text = run_deck(INPUTS / "crank5.dat", tmp_path)
    err = capsys.readouterr().err
    assert "violate loop closure at 8 crank angles" in err
    audit = text[text.index("Audit"):text.index("Why:")]
    flagged = [int(l.split()[0]) for l in audit.splitlines() if len(l.split()) == 9 and l.split()[0].isdigit()]
    assert flagged == list(range(200, 341, 20))
    # notes/fourbar.md: the closed loop at 340 deg gives B = (16.1, 8.0), oms = -6.3523
    row340 = next(l.split() for l in audit.splitlines() if l.split()[:1] == ["340"])
    assert float(row340[5]) == pytest.approx(16.1, abs=0.05)
    assert float(row340[6]) == pytest.approx(8.0, abs=0.05)
    assert float(row340[8]) == pytest.approx(-6.3523, abs=5e-5)
