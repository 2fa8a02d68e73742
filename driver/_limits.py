"""Budgets: absurd requests are refused before they allocate or start.

Every study declares ``estimate(params) -> Estimate`` (:class:`driver._study.Study`, required): from the validated keys alone
(nothing allocated, nothing computed) the memory a run needs and its work, in seconds of one
core of an ordinary 2020s machine, with the key that drives each.  :func:`check` compares the
estimate with the budget and raises a :class:`~driver._deck.DeckError` naming that key, the
estimate and how to raise the limit.

The budget is, by default, half of the memory this process may use (the machine's, or its
cgroup's limit when lower) and :data:`DEFAULT_WORK` seconds of work per deck (per case for a
sweep).  ``--max-memory`` and ``--max-work`` on the command line (or the environment variables
``DRIVER_MAX_MEMORY`` and ``DRIVER_MAX_WORK``, which worker processes inherit) change them.
Estimates are deliberately simple upper-bound-like models (sizes x per-item costs measured
on the shipped decks); they are there to refuse requests that are off by orders of
magnitude, not to predict run times.
"""
from __future__ import annotations

import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from driver._groupspec import Params

__all__ = ["Estimate", "Budget", "budget", "configure", "restore", "check", "parse_size", "parse_seconds",
           "DEFAULT_WORK", "ENV_MEMORY", "ENV_WORK"]

#: default work budget of one deck (one sweep case) [s]
DEFAULT_WORK = 120.0
ENV_MEMORY, ENV_WORK = "DRIVER_MAX_MEMORY", "DRIVER_MAX_WORK"


@dataclass(frozen=True)
class Estimate:
    """What a run needs: bytes and seconds, each with the key that drives it and a phrase."""

    bytes: float
    seconds: float
    memory_key: str | None = None
    work_key: str | None = None
    detail: str = ""

    def __add__(self, other: Estimate) -> Estimate:
        big_m = self if self.bytes >= other.bytes else other
        big_w = self if self.seconds >= other.seconds else other
        return Estimate(self.bytes + other.bytes, self.seconds + other.seconds, big_m.memory_key,
                        big_w.work_key, "; ".join(d for d in (self.detail, other.detail) if d))


@dataclass(frozen=True)
class Budget:
    """Limits of one deck (or sweep case): memory [bytes] and work [s]."""

    memory: float
    work: float


_UNITS = {"": 1, "b": 1, "k": 2**10, "kb": 10**3, "kib": 2**10, "m": 2**20, "mb": 10**6, "mib": 2**20,
          "g": 2**30, "gb": 10**9, "gib": 2**30, "t": 2**40, "tb": 10**12, "tib": 2**40}


def parse_size(text: str) -> float:
    """'4G', '512MiB', '1.5e9' -> bytes (ValueError when not a size)."""
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([a-zA-Z]*)\s*", str(text))
    if not m or m.group(2).lower() not in _UNITS:
        raise ValueError(f"not a memory size: {text!r} (e.g. 4G, 512M, 2GiB)")
    value = float(m.group(1)) * _UNITS[m.group(2).lower()]
    if not (value > 0 and math.isfinite(value)):
        raise ValueError(f"not a positive memory size: {text!r}")
    return value


def parse_seconds(text: str) -> float:
    """'600', '10min', '2h', '90s' -> seconds (ValueError when not a duration)."""
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*(s|sec|min|m|h)?\s*", str(text))
    if not m:
        raise ValueError(f"not a duration: {text!r} (e.g. 600, 10min, 2h)")
    value = float(m.group(1)) * {None: 1, "s": 1, "sec": 1, "min": 60, "m": 60, "h": 3600}[m.group(2)]
    if not (value > 0 and math.isfinite(value)):
        raise ValueError(f"not a positive duration: {text!r}")
    return value


def _available_memory() -> float:
    """Memory this process may use: physical memory, or the cgroup limit when lower [bytes]."""
    try:
        total = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        total = 8.0 * 2**30
    for f in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(f).read_text().strip()
        except OSError:
            continue
        if text.isdigit():
            total = min(total, float(text))
    return total


def budget() -> Budget:
    """The current budget (environment, else defaults)."""
    mem = os.environ.get(ENV_MEMORY)
    work = os.environ.get(ENV_WORK)
    try:
        memory = parse_size(mem) if mem else 0.5 * _available_memory()
    except ValueError:
        memory = 0.5 * _available_memory()
    try:
        seconds = parse_seconds(work) if work else DEFAULT_WORK
    except ValueError:
        seconds = DEFAULT_WORK
    return Budget(memory, seconds)


def configure(max_memory: str | None = None, max_work: str | None = None) -> dict[str, str | None]:
    """Set the budget of this process and of the worker processes it starts (ValueError if malformed).

    Returns the previous settings for :func:`restore`.
    """
    old = {ENV_MEMORY: os.environ.get(ENV_MEMORY), ENV_WORK: os.environ.get(ENV_WORK)}
    if max_memory is not None:
        parse_size(max_memory)
        os.environ[ENV_MEMORY] = str(max_memory)
    if max_work is not None:
        parse_seconds(max_work)
        os.environ[ENV_WORK] = str(max_work)
    return old


def restore(old: dict[str, str | None]) -> None:
    """Undo :func:`configure`."""
    for k, v in old.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v


def _size(b: float) -> str:
    for unit, f in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if b >= f:
            return f"{b / f:.3g} {unit}"
    return f"{b:.0f} bytes"


def _time(s: float) -> str:
    if s >= 86400 * 365:
        return f"{s / (86400 * 365):.3g} years"
    if s >= 86400:
        return f"{s / 86400:.3g} days"
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.3g} s"


class Estimating(Protocol):
    """What :func:`check` needs of a study: its ``estimate`` (every
    :class:`driver._study.Study` has one; the contract lives above this module, which it uses)."""

    @property
    def estimate(self) -> Callable[[Params], Estimate]: ...


def check(study: Estimating, params: Params, what: str = "", lim: Budget | None = None) -> Estimate:
    """Raise DeckError when the study's estimate for ``params`` exceeds the budget.

    ``lim``: the budget to apply (default :func:`budget`, this process's); a caller that sends
    cases to other machines (a Dask cluster does not inherit this process's environment) passes
    its own.
    """
    est = study.estimate(params)
    lim = lim or budget()
    detail = f" ({est.detail})" if est.detail else ""
    if est.bytes > lim.memory:
        raise params.error(est.memory_key, f"{what}needs about {_size(est.bytes)} of memory{detail}, beyond the "
                           f"limit of {_size(lim.memory)}; refused before allocating anything (raise the limit "
                           "with --max-memory SIZE, e.g. --max-memory 32G, if the machine really has it)")
    if est.seconds > lim.work:
        raise params.error(est.work_key, f"{what}is about {_time(est.seconds)} of work{detail}, beyond the limit "
                           f"of {_time(lim.work)} per run; refused before starting (raise the limit with "
                           "--max-work SECONDS, e.g. --max-work 2h)")
    return est
