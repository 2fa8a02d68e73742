"""The report page's animation exported for slides: ``--animation gif`` (Pillow) or ``mp4``
(ffmpeg, where it exists), from the same MechanismFrames the page plays.
"""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
pytest.importorskip("matplotlib")
pytest.importorskip("PIL")

import driver
from driver._cli import main

PIL = pytest.importorskip("PIL.Image")

DECK = "&fourbar\n fixed_link = 12, crank = 5, coupler = 15, rocker = 9, method = 'exact', step_deg = 10\n/\n"


def test_the_animation_moves_the_parts_of_the_frames():
    """Every frame of the export draws the frames' own points: the crank from its pivot to the
    frame's crank pin, the coupler to the frame's B, a link through a missing point hidden."""
    from driver.fourbar._report import animation_frames
    from driver.plotting import mechanism_animation
    r = driver.run(DECK, name="four")
    frames = animation_frames(r.params, r, 36)
    anim = mechanism_animation(frames)
    anim._draw_was_started = True   # drawn frame by frame here, not saved
    ax = anim._fig.axes[0]
    lines = [ln for ln in ax.get_lines() if ln.get_linewidth() == 3.0]   # the links, in frames.links order
    assert len(lines) == len(frames.links)
    for k in (0, 7, 20, 35):
        anim._func(k)
        for line, link in zip(lines, frames.links):
            x, y = line.get_data()
            assert np.allclose(np.column_stack([x, y]), frames.points[k, list(link.points)])
        assert frames.labels[k] in anim._fig.axes[0].get_title()


def test_gif_from_the_command_line(tmp_path):
    deck = tmp_path / "four.dat"
    deck.write_text(DECK)
    assert main([str(deck), "-o", str(tmp_path / "out"), "-q", "--animation", "gif"]) == 0
    gif = tmp_path / "out" / "four_animation.gif"
    img = PIL.open(gif)
    assert img.format == "GIF" and img.n_frames == 90     # 180 frames of the page, every other one
    assert img.info["duration"] == 40 and img.info.get("loop") == 0   # 25 frames a second, looping
    img.seek(0)
    first = np.asarray(img.convert("L"), dtype=float)
    img.seek(20)
    later = np.asarray(img.convert("L"), dtype=float)
    assert first.std() > 5 and np.abs(first - later).mean() > 0.1   # a drawing, and it moves
    assert gif.stat().st_mode & 0o777 == 0o644
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.startswith(".")]   # no temporary left


def test_write_an_animation_from_python(tmp_path):
    r = driver.run(DECK, name="four")
    written = driver.write(r, tmp_path, animation="gif")
    assert written[-1] == tmp_path / "four_animation.gif" and written[-1].is_file()
    with pytest.raises(ValueError, match="animation format"):
        from driver.fourbar._report import animation_frames
        from driver.plotting import save_animation
        save_animation(animation_frames(r.params, r, 12), tmp_path / "x", "avi")


@pytest.mark.parametrize("fmt", ["gif", "mp4", "GIF"])
def test_plot_format_gif_names_the_animation_option(tmp_path, capsys, fmt):
    """The issue's spelling, --plot-format gif, is exit 2 naming --animation (the figures' formats
    are png, svg, pdf); nothing is written."""
    deck = tmp_path / "four.dat"
    deck.write_text(DECK)
    with pytest.raises(SystemExit) as info:
        main([str(deck), "-o", str(tmp_path / "out"), "--plot-format", fmt])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert f"--animation {fmt.lower()}" in err and "png, svg, pdf" in err, err
    assert not (tmp_path / "out").exists()


def test_mp4_without_ffmpeg_is_a_clear_error(tmp_path, monkeypatch):
    import matplotlib.animation
    monkeypatch.setattr(matplotlib.animation.writers, "is_available", lambda name: False)
    deck = tmp_path / "four.dat"
    deck.write_text(DECK)
    from driver._deck import read_deck
    from driver._dispatch import run_deck
    oc = run_deck(read_deck(deck), tmp_path / "out", [], False, animation="mp4")
    assert oc.exit_code == 1 and any("needs ffmpeg" in str(m) for m in oc.messages)
    assert (tmp_path / "out" / "four.out").is_file() and not (tmp_path / "out" / "four_animation.mp4").exists()


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="no ffmpeg on PATH (MP4 needs it; GIF does not)")
def test_mp4_where_ffmpeg_exists(tmp_path):
    r = driver.run(DECK, name="four")
    path = driver.write(r, tmp_path, animation="mp4")[-1]
    assert path.suffix == ".mp4" and path.read_bytes()[4:8] == b"ftyp"
