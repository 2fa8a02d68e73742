"""No output is written through a symbolic link planted in OUTDIR (issue 36, item 2).

For every kind of output -- a study's ``.out``, ``--json``, tidy tables (CSV, Parquet), figures,
the report page; a sweep's tables and case files; an optimisation's ``.optimum.*``, history,
evaluations table and journal (with and without ``--resume``); a synthesis's outputs; an
example deck copied out; the temporaries of a killed run -- a run first learns the names its
outputs have (a clean run into another folder), then a link is planted at each name in OUTDIR,
once pointing nowhere (a dangling link into a folder outside OUTDIR) and once at a victim file
outside OUTDIR.  Every run must leave the victims' bytes as they were and create nothing
outside OUTDIR; each link is replaced by the tool's own regular file (never followed).
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest

from driver._cli import main

FOURBAR = """&fourbar
  fixed_link = 12.0, crank = 5.0, coupler = 15.0, rocker = 9.0
  omega = 5.0, step_deg = 30
/
"""
SWEEP = FOURBAR + "&sweep\n  key1 = 'fourbar.crank', values1 = 2, 3\n/\n"
OPTIMIZE = FOURBAR.replace("step_deg = 30", "step_deg = 10") + """&optimize
  var1 = 'fourbar.coupler', lower1 = 10, upper1 = 20
  maximize = 'mu_min_deg'
  method = 'grid', grid_count = 3
/
"""
SYNTHESIS = """&synthesis
  task = 'function', function = 'log10(x)', x_start = 1.0, x_stop = 2.0
  crank_start_deg = 45.0, crank_range_deg = 60.0
  rocker_start_deg = 135.0, rocker_range_deg = 90.0
  points = 3, fixed_link = 1.0, step_deg = 5, branch = 'open'
/
"""
VICTIM = b"the victim's own bytes\n"


def _outputs(tmp_path: Path, text: str, options: list[str]) -> list[Path]:
    """The files a clean run writes, relative to its OUTDIR."""
    deck = tmp_path / "learn" / "d.dat"
    deck.parent.mkdir()
    deck.write_text(text)
    out = tmp_path / "learn" / "out"
    assert main([str(deck), "-o", str(out), "-q", "-j", "1", *options]) in (0, 1)
    return sorted(p.relative_to(out) for p in out.rglob("*") if p.is_file())


def _plant(out: Path, names: list[Path], target_of) -> dict[Path, Path]:
    links = {}
    for rel in names:
        link = out / rel
        link.parent.mkdir(parents=True, exist_ok=True)
        target = target_of(rel)
        link.symlink_to(target)
        links[link] = target
    return links


def _untouched(tmp_path: Path, victims: dict[Path, Path], dangling: bool) -> None:
    outside = tmp_path / "outside"
    assert not any(outside.rglob("*")), f"created outside OUTDIR: {sorted(outside.rglob('*'))}"
    for link, target in victims.items():
        if not dangling:
            assert target.read_bytes() == VICTIM, f"{target} changed through {link}"
        assert not link.is_symlink() or not os.path.lexists(link) or os.readlink(link) == str(target)


@pytest.mark.parametrize("dangling", [True, False], ids=["dangling", "victim"])
@pytest.mark.parametrize("kind,text,options,extra", [
    ("study", FOURBAR, ["--json", "--csv", "--format", "parquet", "--plot", "--report"], []),
    ("sweep", SWEEP, ["--csv", "--json"], []),
    ("optimize", OPTIMIZE, ["--json", "--csv", "--plot"], ["d.journal.jsonl"]),
    ("synthesis", SYNTHESIS, ["--json", "--csv", "--plot"], []),
])
def test_no_output_follows_a_planted_link(tmp_path, capsys, dangling, kind, text, options, extra):
    names = [n for n in _outputs(tmp_path, text, options) if ".sweep" not in n.parts[0]]
    names += [Path(e) for e in extra]
    names.append(Path(f".d.out.{2**22 + 12345}.k3j.tmp"))   # a killed run's temporary (a dead pid)
    assert len(names) >= 4, names
    (tmp_path / "outside").mkdir()
    (tmp_path / "victims").mkdir()

    def target_of(rel: Path) -> Path:
        if dangling:
            return tmp_path / "outside" / rel.name
        victim = tmp_path / "victims" / rel.name
        victim.write_bytes(VICTIM)
        return victim

    deck = tmp_path / "d.dat"
    deck.write_text(text)
    out = tmp_path / "out"
    links = _plant(out, names, target_of)
    rc = main([str(deck), "-o", str(out), "-q", "-j", "1", *options])
    assert rc in (0, 1), capsys.readouterr().err
    _untouched(tmp_path, links, dangling)
    for link in links:
        if link.name.endswith(".tmp") or link.name.endswith(".jsonl"):
            continue
        assert link.is_file() and not link.is_symlink(), f"{link.name} was not written"


@pytest.mark.parametrize("dangling", [True, False], ids=["dangling", "victim"])
def test_the_journal_of_a_resumed_optimisation_follows_no_link(tmp_path, capsys, dangling):
    """Issue 36 item 2: with --resume the journal was appended to the file the link points to,
    and without it a dangling link made a file outside OUTDIR."""
    (tmp_path / "outside").mkdir()
    victim = tmp_path / "outside" / "victim.txt"
    if not dangling:
        victim.write_bytes(VICTIM)
    deck = tmp_path / "d.dat"
    deck.write_text(OPTIMIZE)
    out = tmp_path / "out"
    out.mkdir()
    (out / "d.journal.jsonl").symlink_to(victim)
    assert main([str(deck), "-o", str(out), "-q", "-j", "1", "--resume"]) == 0
    if dangling:
        assert not victim.exists() and not any((tmp_path / "outside").iterdir())
    else:
        assert victim.read_bytes() == VICTIM
        assert "the journal cannot be read (a symbolic link" in capsys.readouterr().err
    assert not os.path.lexists(out / "d.journal.jsonl")   # removed with the run's outputs complete


@pytest.mark.parametrize("dangling", [True, False], ids=["dangling", "victim"])
def test_the_journal_of_a_running_optimisation_follows_no_link(tmp_path, monkeypatch, dangling):
    """The journal while the run goes (the run stopped before its outputs are written)."""
    import driver.optimize as opt
    (tmp_path / "outside").mkdir()
    victim = tmp_path / "outside" / "victim.txt"
    if not dangling:
        victim.write_bytes(VICTIM)
    deck = tmp_path / "d.dat"
    deck.write_text(OPTIMIZE)
    out = tmp_path / "out"
    out.mkdir()
    (out / "d.journal.jsonl").symlink_to(victim)

    def stop(*_a, **_k):
        raise KeyboardInterrupt
    monkeypatch.setattr(opt, "_write", stop)
    for resume in (False, True):
        if not os.path.lexists(out / "d.journal.jsonl"):
            (out / "d.journal.jsonl").symlink_to(victim)
        with pytest.raises(KeyboardInterrupt):
            opt.optimize(deck, out, jobs=1, resume=resume)
        journal = out / "d.journal.jsonl"
        assert journal.is_file() and not journal.is_symlink() and journal.read_text().count("\n") == 3
        assert (not victim.exists()) if dangling else victim.read_bytes() == VICTIM
        journal.unlink()


@pytest.mark.parametrize("dangling", [True, False], ids=["dangling", "victim"])
def test_an_example_deck_is_not_copied_through_a_link(tmp_path, capsys, dangling):
    (tmp_path / "outside").mkdir()
    victim = tmp_path / "outside" / "victim.dat"
    if not dangling:
        victim.write_bytes(VICTIM)
    out = tmp_path / "out"
    out.mkdir()
    (out / "crank5.dat").symlink_to(victim)
    rc = main(["--example", "crank5.dat", "-o", str(out)])
    assert rc == 1 and "exists; not overwritten" in capsys.readouterr().err
    assert (not victim.exists()) if dangling else victim.read_bytes() == VICTIM


# ----------------------------------------------------------------------------- an output set, whole or not at all

@pytest.mark.parametrize("kind,text,options", [
    ("study", FOURBAR, ["--csv", "--json", "--plot"]),
    ("optimize", OPTIMIZE, ["--csv", "--json", "--plot"]),     # put .optimum.dat and .optimum.out in place
    ("synthesis", SYNTHESIS, ["--csv", "--json", "--plot"]),
])
def test_an_output_set_is_written_whole_or_not_at_all(tmp_path, capsys, kind, text, options):
    """Issue 36 item 7: an optimisation whose .out could not be written still put its optimum's
    files in place.  A folder where the .out goes fails the run (exit 1, one line) with nothing
    of its set in place, whatever the engine."""
    deck = tmp_path / "d.dat"
    deck.write_text(text)
    out = tmp_path / "out"
    (out / "d.out").mkdir(parents=True)
    assert main([str(deck), "-o", str(out), "-q", "-j", "1", *options]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "d.out" in err[0] and "folder" in err[0], err
    left = sorted(p.name for p in out.iterdir() if p.name not in ("d.out", "d.journal.jsonl"))
    assert left == [], f"in place although the set failed: {left}"
    assert not any(p.is_file() for p in (out / "d.out").iterdir())
