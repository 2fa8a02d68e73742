"""Command line: ``python -m driver DECK [DECK ...] [-o OUTDIR] [--csv|--format F] [--json] [--plot] [--compare]``.

Each deck runs on its own; the exit status is 0 when every deck succeeded,
2 when any deck had bad input (nothing written for that deck), 1 when a run
failed otherwise (e.g. an optimiser did not converge; its outputs say so).
Only argument parsing lives here; running is :mod:`driver._runner` and
:mod:`driver.sweep`, :mod:`driver.optimize`, :mod:`driver.synthesis`.  Heavy modules (pandas, the kernels, the studies) are
imported after parsing, so ``--help`` and ``--version`` answer at once.
"""
from __future__ import annotations

import argparse
import contextlib
import errno
import os
import signal
import sys
import threading
import traceback
from pathlib import Path
from typing import Any

from driver import __version__
from driver import _limits as limits
from driver._export import FORMATS
from driver._extras import MissingExtra, require
from driver._formats import ANIMATION_FORMATS, PLOT_FORMATS
from driver._outcome import ExitCode, Outcome, RunOutcome, SweepOutcome
from driver._study import study_names

__all__ = ["main", "run_deck", "say", "ExitCode"]


def _fs_error(exc: OSError) -> str:
    """One line for a file-system fault: the path and the reason in words."""
    reasons = {errno.ENOSPC: "no space left on the device", errno.EFBIG: "file too large (file size limit)",
               errno.EROFS: "read-only file system", errno.EACCES: "permission denied",
               errno.EPERM: "not permitted", errno.ENOTDIR: "a part of the path is a file, not a folder",
               errno.EISDIR: "is a folder, not a file", errno.EDQUOT: "disk quota exceeded",
               errno.ENAMETOOLONG: "file name too long"}
    from driver._atomic import LinkRefused
    if isinstance(exc, LinkRefused):
        return f"refusing {exc.filename}: {exc.strerror}"
    if exc.errno == errno.EBUSY and exc.__class__.__name__ == "SweepBusy":
        return f"{exc.strerror} ({exc.filename})"
    reason = reasons.get(exc.errno or 0, exc.strerror or str(exc))
    if exc.strerror and exc.errno not in reasons:
        reason = exc.strerror
    where = exc.filename if exc.filename is not None else "output"
    return f"cannot write {where}: {reason}"


def _plot_format(text: str) -> str:
    """``--plot-format``'s value; an animation format is refused naming the option that writes it."""
    if text.lower() in ANIMATION_FORMATS:
        raise argparse.ArgumentTypeError(f"'{text}' is not a figure format ({', '.join(PLOT_FORMATS)}): the "
                                         f"mechanism's animation is written with --animation {text.lower()}")
    return text


def run_deck(path: Path, outdir: Path, formats: list[str], plot: bool | str, progress: bool,
             quiet: bool = False, sweep_options: dict | None = None, summary_json: bool = False,
             report: bool = False, animation: str | None = None) -> int:
    """Run one deck; returns its exit status. Errors are printed, never raised.

    ``sweep_options`` (jobs, scheduler, resume) apply when the deck has a &sweep or an
    &optimize group (a sweep's cases always write their summary as JSON); given for any other
    deck, they are reported as ignored.  ``summary_json`` writes a single run's summary as
    ``<stem>.json``.  ``report`` also writes the deck's report page ``<stem>.html``
    (:mod:`driver._report_page`) once its run has written its outputs; ``animation`` ('gif',
    'mp4') the mechanism's animation ``<stem>_animation.<fmt>``.
    """
    from driver._atomic import NameTooLong
    from driver._deck import DeckError, read_deck
    from driver._dispatch import run_deck as run_by_engine
    from driver._runner import name_too_long
    try:
        deck = read_deck(path)
        given = [opt for opt, key in (("-j/--jobs", "jobs"), ("--scheduler", "scheduler"), ("--resume", "resume"))
                 if (sweep_options or {}).get(key) and not ({"sweep", "optimize"} & set(deck.groups))]
        outcome = run_by_engine(deck, outdir, formats, plot, progress, summary_json=summary_json, report=report,
                                notify=_notify, animation=animation, **(sweep_options or {}))
    except DeckError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return ExitCode.BAD_INPUT
    except NameTooLong as exc:   # an output name known only once computed (a figure's): nothing was written
        stem, name = Path(path).stem, Path(exc.filename).name
        what = (name_too_long(len(os.fsencode(stem)), name[len(stem):]) if name.startswith(stem)
                else f"cannot write {exc.filename}: {exc.strerror}")
        print(f"error: {path}: {what}; nothing written", file=sys.stderr)
        return ExitCode.BAD_INPUT
    except MissingExtra as exc:
        print(f"error: {path}: {exc}", file=sys.stderr)
        return ExitCode.FAILED
    except (KeyboardInterrupt, BrokenPipeError):
        raise
    except OSError as exc:   # the file system: one line naming the path, then the next deck
        print(f"error: {path}: {_fs_error(exc)}", file=sys.stderr)
        return ExitCode.FAILED
    except MemoryError:
        print(f"error: {path}: out of memory (see --max-memory)", file=sys.stderr)
        return ExitCode.FAILED
    except Exception as exc:  # a bug or an unexpected numerical failure: say so plainly
        print(f"error: {path}: run failed: {exc.__class__.__name__}: {exc}", file=sys.stderr)
        if os.environ.get("DRIVER_DEBUG"):
            traceback.print_exc()
        return ExitCode.FAILED
    if given and isinstance(outcome, RunOutcome):   # once the deck is known to be valid (not after bad input)
        print(f"warning: {path}: {', '.join(given)} apply to sweep and optimisation decks "
              f"(a &sweep or &optimize group) only; ignored for this deck", file=sys.stderr)
    say(outcome, quiet)
    return outcome.exit_code


def _notify(line: str) -> None:
    """What an engine says at once, before its outcome (a sweep's Ctrl-C notice): a line on stderr."""
    print(line, file=sys.stderr, flush=True)


def say(outcome: Outcome, quiet: bool = False) -> None:
    """Print an engine's outcome: its warnings and errors on stderr, in order; unless ``quiet``,
    its progress notes, its summary line and the files written on stdout."""
    for message in outcome.messages:
        print(message, file=sys.stderr)
    if quiet:
        return
    for line in _stdout_lines(outcome):
        print(line)


def _stdout_lines(outcome: Outcome) -> list[str]:
    """What a deck's run says on stdout: for a sweep its notes, its summary line and the files
    written (its own tables in one line); for a comparison each deck's agreement lines, then the
    totals; otherwise the files written, then the notes (an optimisation's result and the designs
    it computed)."""
    compare = sys.modules.get("driver._compare")   # not imported (pandas!) unless --compare ran
    if compare is not None and isinstance(outcome, compare.CompareOutcome):
        return [line for c in outcome.comparisons for line in compare.compare_text(c)] + \
            (["Total", *outcome.totals] if outcome.totals else [])
    if isinstance(outcome, SweepOutcome):
        oc, out = outcome, outcome.outdir or Path(".")
        own = [out / f"{oc.name}.out", out / f"{oc.name}_summary.csv", out / f"{oc.name}_summary.parquet"]
        if oc.batch:
            speed = (f"{oc.seconds:.2f} s, {oc.n_cases / max(oc.seconds, 1e-9):.0f} cases/s "
                     f"({oc.workers}, batch path, chunk {oc.chunk})")
        else:
            speed = f"{oc.seconds:.2f} s ({oc.workers}, chunk {oc.chunk})"
        return [*oc.notes, f"sweep {oc.deck}: {oc.n_ok} of {oc.n_cases} cases ok, {oc.n_kept} kept, {speed}",
                f"wrote {own[0]} and {out / oc.name}_summary.{{csv,parquet}}",
                *(f"wrote {p}" for p in oc.written if p not in own)]
    return [*(f"wrote {p}" for p in outcome.written), *outcome.notes]


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled like Ctrl-C: temporaries removed, finished outputs kept."""


def _on_sigterm(signum: int, frame: object) -> None:
    raise Terminated()


def keys_help(group: str) -> str | None:
    """Every key of namelist group ``group`` with kind, units, default and doc; None if no such group."""
    from driver._study import group_spec
    spec = group_spec(group)
    if spec is None:
        return None
    lines = [f"&{spec.name}: {spec.doc}".rstrip(": "), ""]
    for name, key in spec.keys.items():
        req = "required" if key.required else f"default {key.default!r}"
        choices = f"; one of {', '.join(map(repr, key.choices))}" if key.choices else ""
        units = f" [{key.units}]" if key.units else ""
        lines.append(f"  {name:<22} {key.kind:<7}{units} ({req}{choices})")
        if key.doc:
            lines.append(f"  {'':<22} {key.doc}")
    return "\n".join(lines)


def _examples(args: argparse.Namespace) -> int:
    """--examples: list the shipped decks; --example NAME: copy one out."""
    from driver import _example_decks as example_decks
    try:
        if args.examples:
            names = example_decks.list_examples()
            width = max(map(len, names))
            print(f"example decks ({example_decks.examples_dir()}); copy one with: python -m driver --example NAME")
            for name in names:
                text = example_decks.describe(name) or "(the listing's terminal input: p q r s, omega, increment)"
                print(f"  {name:<{width}}  {text[:100] + ('...' if len(text) > 100 else '')}")
        for name in args.example:
            target = example_decks.copy_example(name, args.outdir or Path("."))
            print(f"copied {target}; run it with: python -m driver {target}")
    except KeyError as exc:
        print(f"error: {exc.args[0]}", file=sys.stderr)
        return ExitCode.BAD_INPUT
    except BrokenPipeError:   # e.g. piped into head
        sys.stderr.close()
    except OSError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return ExitCode.FAILED
    return ExitCode.OK


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of worker processes, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"needs at least 1 worker process, got {value} "
                                         "(leave -j out to use every core)")
    return value


def build_parser() -> argparse.ArgumentParser:
    studies = ", ".join(f"&{g}" for g in study_names())
    parser = argparse.ArgumentParser(
        prog="python -m driver",
        description="Run mechanism-analysis decks (Fortran namelist files) and write "
                    "fixed-format tables to OUTDIR/<deck stem>.out.",
        epilog=f"Study groups: {studies}; a &sweep group turns a deck into a study over "
               "several cases, an &optimize group into an optimisation. 'python -m driver --keys GROUP' lists a "
               "group's keys (also --keys sweep, --keys optimize); "
               "'python -m driver --examples' lists the shipped example decks. "
               "Exit status: 0 all decks succeeded, 1 a run failed, 2 bad input.",
    )
    parser.add_argument("decks", nargs="*", type=Path, metavar="DECK", help="input deck(s), e.g. inputs/crank5.dat")
    parser.add_argument("-o", "--outdir", type=Path, default=None,
                        help="output folder (default: outputs/, created when missing); "
                             "with --example, where the deck is copied (default: here)")
    parser.add_argument("--csv", action="store_true", help="also write the tidy table as <stem>.csv")
    parser.add_argument("--format", dest="formats", action="append", choices=FORMATS, default=[],
                        help="also write the tidy table in this format (repeatable)")
    parser.add_argument("--json", action="store_true",
                        help="also write the run's record as <stem>.json, one schema for every engine "
                             "(driver/record.schema.json, docs/json.md): engine, study, name, deck, ok, exit_code, "
                             "messages, summary, files and the engine's own section (a single run's failure and "
                             "warnings, a sweep's cases, an optimisation's x, fun, constraints, a synthesis's "
                             "linkage and checks); with --compare, one record per deck on stdout (JSON Lines)")
    parser.add_argument("--plot", action="store_true", help="write figures <stem>_<name>.png (see --plot-format)")
    parser.add_argument("--plot-format", choices=PLOT_FORMATS, default=None, type=_plot_format,
                        help="figure file format (implies --plot; default png); the same inputs give "
                             "byte-identical files")
    parser.add_argument("--report", action="store_true",
                        help="also write a self-contained report page <stem>.html (figures, tables, the deck, "
                             "warnings, the comparison with the published tables, an animation of the mechanism; "
                             "opens offline in any browser and prints)")
    parser.add_argument("--animation", choices=ANIMATION_FORMATS, default=None,
                        help="also write the mechanism's animation <stem>_animation.gif (or .mp4, needs ffmpeg) for "
                             "slides: the frames the report page plays (a sweep's best case, an optimisation's optimum, "
                             "a synthesised linkage with its targets)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print only warnings and errors")
    parser.add_argument("--keys", metavar="GROUP", help="list the keys of a namelist group and exit")
    parser.add_argument("--examples", action="store_true",
                        help="list the example decks shipped with the package and exit")
    parser.add_argument("--example", metavar="NAME", action="append", default=[],
                        help="copy the shipped example deck NAME.dat here (or into -o DIR) and exit (repeatable)")
    parser.add_argument("--compare", action="store_true",
                        help="compare each deck's run with the published tables in published/ (cell by cell, "
                             "with reasons; writes nothing); exit 0 when every reproducible cell agrees")
    parser.add_argument("-j", "--jobs", type=_positive_int, default=None,
                        help="sweeps and optimisations: worker processes, at least 1 (default: all cores)")
    parser.add_argument("--scheduler", default=None, metavar="ADDRESS",
                        help="sweeps and optimisations: run cases on this Dask distributed scheduler")
    parser.add_argument("--resume", action="store_true",
                        help="sweeps: skip cases whose outputs are already complete; "
                             "optimisations: replay the run's journal and compute only new designs")
    parser.add_argument("--max-memory", metavar="SIZE", default=None,
                        help="refuse a deck (a sweep case) whose estimated memory is larger "
                             "(e.g. 8G, 512M; default: half of this machine's memory)")
    parser.add_argument("--max-work", metavar="SECONDS", default=None,
                        help="refuse a deck (a sweep case) whose estimated work is longer "
                             "(e.g. 600, 30min, 2h; default: 2 min)")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return _main(parser, args)
    except ImportError as exc:   # e.g. the kernels are not built: driver._fortran says what to do
        print(f"error: {exc}", file=sys.stderr)
        return ExitCode.FAILED


def _main(parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
    if args.keys:
        group = args.keys.lstrip("&").lower()
        text = keys_help(group)
        if text is None:
            from driver._runner import CONTROL_GROUPS
            known = ", ".join(f"&{g}" for g in (*study_names(), *CONTROL_GROUPS))
            print(f"error: --keys: no namelist group &{group} (known groups: {known})", file=sys.stderr)
            return ExitCode.BAD_INPUT
        try:
            print(text)
        except BrokenPipeError:  # e.g. piped into head
            sys.stderr.close()
        return ExitCode.OK
    if args.examples or args.example:
        return _examples(args)
    if not args.decks:
        parser.error("no deck given (python -m driver --examples lists the shipped example decks)")
    if args.compare and args.json:
        return _compare_json(args.decks)
    if args.compare:
        from driver._compare import CompareOutcome, compare_decks
        try:
            compared = compare_decks(args.decks, on_deck=say)   # each deck's lines as soon as it is compared
            if compared.totals:
                say(CompareOutcome(totals=compared.totals))
            return compared.exit_code
        except BrokenPipeError:
            sys.stderr.close()
            return ExitCode.OK
    try:
        configured = limits.configure(args.max_memory, args.max_work)
    except ValueError as exc:
        parser.error(str(exc))
    formats = list(dict.fromkeys((["csv"] if args.csv else []) + args.formats))
    needs = ([("plot", "--plot")] if (args.plot or args.plot_format) else []) + \
        ([("plot", "--report")] if args.report else []) + ([("plot", "--animation")] if args.animation else []) + \
        ([("parquet", "--format parquet")]
             if "parquet" in formats else []) + ([("dask", "--scheduler")] if args.scheduler else [])
    for extra, option in needs:
        try:
            require(extra)
        except MissingExtra as exc:
            parser.error(f"{option}: {exc}")
    outdir = args.outdir or Path("outputs")
    progress = sys.stderr.isatty() and not args.quiet and not os.environ.get("CI")
    plot: bool | str = args.plot_format or args.plot
    sweep_options = {"jobs": args.jobs, "scheduler": args.scheduler, "resume": args.resume}
    status: int = ExitCode.OK   # the worst deck's status (run_deck returns a plain int)
    handlers = _install_signals()
    try:
        for deck in args.decks:
            try:
                status = max(status, run_deck(deck, outdir, formats, plot, progress, args.quiet,
                                             sweep_options, summary_json=args.json, report=args.report,
                                             animation=args.animation))
                sys.stdout.flush()
            except BrokenPipeError:   # stdout closed early (e.g. piped into head): the files are
                _quiet_stdout()       # written; go on with the other decks without printing
    except KeyboardInterrupt as exc:
        what = "terminated" if isinstance(exc, Terminated) else "interrupted"
        print(f"{what}: finished outputs are complete; no partial file was left", file=sys.stderr)
        return ExitCode.TERMINATED if isinstance(exc, Terminated) else ExitCode.INTERRUPTED
    finally:
        _restore_signals(handlers)
        limits.restore(configured)
    return status


def _compare_json(decks: list[Path]) -> int:
    """--compare --json: each deck's comparison as one line of JSON on stdout (its record,
    driver._record), its errors on stderr too; the worst deck's exit status."""
    from driver._compare import compare_decks
    from driver._record import compare_record, record_text
    status: int = ExitCode.OK
    try:
        for deck in decks:
            part = compare_decks([deck])
            for message in part.messages:
                print(message, file=sys.stderr)
            print(record_text(compare_record(part, deck), indent=None), end="", flush=True)
            status = max(status, part.exit_code)
    except BrokenPipeError:
        _quiet_stdout()
    return status


def _quiet_stdout() -> None:
    """After a broken pipe: point stdout at /dev/null so the interpreter's final flush is silent."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def _install_signals() -> dict[signal.Signals, Any]:
    """SIGTERM like Ctrl-C; SIGXFSZ ignored so a file size limit is an EFBIG error, not a kill."""
    old: dict[signal.Signals, Any] = {}
    if threading.current_thread() is not threading.main_thread():
        return old
    for sig, handler in ((getattr(signal, "SIGTERM", None), _on_sigterm),
                         (getattr(signal, "SIGXFSZ", None), signal.SIG_IGN)):
        if sig is not None:
            old[sig] = signal.signal(sig, handler)
    return old


def _restore_signals(old: dict[signal.Signals, Any]) -> None:
    for sig, handler in old.items():
        signal.signal(sig, handler)
