"""Guard: every loop marked ``! hot-loop:`` in fortran/*.f90 is vectorised by the compiler.

The kernels' speed rests on their hot loops being vectorised.  That is easy to lose
silently: the four-bar kernel ran 3.7x slower for weeks after a commit added call sites
of an elemental helper and gfortran stopped inlining it ("not vectorized: control flow
in loop").  So the hot loops are marked in the source (a ``! hot-loop: <name>`` comment
on the line before the ``do``) and this test compiles every kernel with exactly the flags
of the project's build (read from the build directory's compile_commands.json, or from
a fresh ``meson setup`` when there is none) plus ``-fopt-info-vec-optimized``, and fails
naming each marked loop the compiler did not report vectorised.

Deterministic: it reads the compiler's own report, it does not time anything.
"""
from __future__ import annotations

import json
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FORTRAN = ROOT / "fortran"
MARK = re.compile(r"^\s*!\s*hot-loop:\s*(?P<name>.+?)\s*$", re.IGNORECASE)
DO = re.compile(r"^\s*(?:\w+\s*:\s*)?do\b", re.IGNORECASE)
VECTORISED = re.compile(r"^(?P<file>[^:\s]+\.f90):(?P<line>\d+):\d+: optimized: loop vectorized", re.MULTILINE)

pytestmark = pytest.mark.skipif(shutil.which("gfortran") is None, reason="needs gfortran (the project's compiler)")


def kernel_sources() -> list[Path]:
    """The Fortran sources in build order, as listed in fortran/meson.build (the shared building
    blocks, then each study's line)."""
    text = (FORTRAN / "meson.build").read_text().split("custom_target(")[0]   # not f2py's outputs
    names = re.findall(r"'([^']+\.f90)'", text)
    assert names[:2] == ["kinds.f90", "vecmath.f90"], "fortran/meson.build: kinds.f90 and vecmath.f90 first"
    return [FORTRAN / name for name in names]


def marked_loops(path: Path) -> dict[int, str]:
    """{line of the marked ``do`` statement: marker name} of one source file."""
    lines = path.read_text().splitlines()
    found: dict[int, str] = {}
    for i, line in enumerate(lines):
        m = MARK.match(line)
        if not m:
            continue
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        assert DO.match(nxt), f"{path.name}:{i + 1}: hot-loop marker not followed by a do statement"
        found[i + 2] = m.group("name")
    return found


def _compile_commands() -> list[dict] | None:
    tag = "cp{}{}".format(*sys.version_info[:2])
    for cand in [ROOT / "build" / tag, *sorted((ROOT / "build").glob("*"))]:
        f = cand / "compile_commands.json"
        if f.is_file():
            return json.loads(f.read_text())
    return None


def project_flags(tmp_path: Path) -> list[str]:
    """The Fortran compiler flags of the project's build of the kernels (warnings and
    paths dropped): from the existing build directory, else from a fresh meson setup."""
    cmds = _compile_commands()
    if cmds is None:
        meson = Path(sys.executable).with_name("meson")
        build = tmp_path / "meson-build"
        subprocess.run([str(meson) if meson.exists() else "meson", "setup", str(build), str(ROOT)],
                       check=True, capture_output=True, text=True)
        cmds = json.loads((build / "compile_commands.json").read_text())
    for entry in cmds:
        if entry["file"].endswith("fortran/kinds.f90"):
            args = shlex.split(entry["command"])
            break
    else:
        raise AssertionError("compile_commands.json has no entry for fortran/kinds.f90")
    keep, skip_next = [], False
    for a in args[1:]:
        if skip_next:
            skip_next = False
            continue
        if a in ("-o", "-J", "-MQ", "-MF", "-I"):
            skip_next = True
            continue
        if a.startswith(("-o", "-J", "-I", "-M", "-W", "-fdiagnostics-color", "-D")) or a == "-c" \
                or not a.startswith("-"):
            continue
        keep.append(a)
    return keep


def unvectorised(sources: list[Path], flags: list[str], work: Path) -> tuple[list[str], int]:
    """Compile sources in order with flags + -fopt-info-vec-optimized; return the marked
    loops not reported vectorised ('file:line name') and the number of marked loops."""
    work.mkdir(parents=True, exist_ok=True)
    missing, total = [], 0
    for src in sources:
        res = subprocess.run(["gfortran", *flags, "-fopt-info-vec-optimized", "-c", str(src),
                              "-J", str(work), "-I", str(work), "-o", str(work / (src.stem + ".o"))],
                             capture_output=True, text=True, cwd=work)
        assert res.returncode == 0, f"gfortran failed on {src.name}:\n{res.stderr[-3000:]}"
        done = {int(m.group("line")) for m in VECTORISED.finditer(res.stderr)
                if Path(m.group("file")).name == src.name}
        marks = marked_loops(src)
        total += len(marks)
        missing += [f"{src.name}:{line} {name}" for line, name in sorted(marks.items()) if line not in done]
    return missing, total


@pytest.fixture(scope="module")
def flags(tmp_path_factory) -> list[str]:
    return project_flags(tmp_path_factory.mktemp("flags"))


def test_every_kernel_has_marked_hot_loops():
    counts = {s.name: len(marked_loops(s)) for s in kernel_sources()}
    for name in ("vecmath.f90", "fourbar.f90", "fourbar_forces.f90", "manipulator.f90", "ujoint.f90", "slidercrank.f90"):
        assert counts.get(name, 0) >= 2, f"{name}: no hot loops marked ({counts})"


def test_marked_hot_loops_vectorised(flags, tmp_path):
    missing, total = unvectorised(kernel_sources(), flags, tmp_path)
    assert total >= 30
    assert not missing, ("hot loops not vectorised with the project's flags "
                         f"({' '.join(flags)}):\n  " + "\n  ".join(missing))


@pytest.mark.parametrize("arch", ["portable", "native"])
def test_marked_hot_loops_vectorised_on_both_builds(flags, tmp_path, arch):
    """Both build flavours (meson option native=false/true) keep the loops vectorised."""
    base = [f for f in flags if not f.startswith(("-march=", "-mprefer-vector-width", "-mtune="))]
    extra = ["-march=native", "-mprefer-vector-width=512"] if arch == "native" else []
    missing, _ = unvectorised(kernel_sources(), base + extra, tmp_path)
    assert not missing, f"{arch} build: hot loops not vectorised:\n  " + "\n  ".join(missing)


def test_guard_catches_a_call_in_a_marked_loop(flags, tmp_path):
    """The guard can fail: a marked loop calling an external procedure is reported."""
    src = tmp_path / "bad.f90"
    src.write_text("""module bad
  implicit none
  interface
    subroutine opaque(x, y)
      double precision, intent(in) :: x
      double precision, intent(out) :: y
    end subroutine opaque
  end interface
contains
  subroutine loop(n, x, y)
    integer, intent(in) :: n
    double precision, intent(in) :: x(n)
    double precision, intent(out) :: y(n)
    integer :: k
    ! hot-loop: calls an opaque procedure
    do k = 1, n
      call opaque(x(k), y(k))
    end do
    ! hot-loop: plain arithmetic
    do k = 1, n
      y(k) = y(k)*x(k) + 1d0
    end do
  end subroutine loop
end module bad
""")
    missing, total = unvectorised([src], flags, tmp_path / "o")
    assert total == 2
    assert missing == ["bad.f90:16 calls an opaque procedure"]


def test_guard_catches_the_regressed_fourbar_kernel(flags, tmp_path):
    """The four-bar kernel before this guard (tests/data/fourbar_regressed.f90, with its
    main loop marked): gfortran 12 does not inline its per-element vsincos there, so
    the main loop is not vectorised and the guard reports it."""
    ver = subprocess.run(["gfortran", "-dumpversion"], capture_output=True, text=True).stdout.strip()
    if ver.split(".")[0] != "12":
        pytest.skip(f"the regression was observed with gfortran 12 (this is {ver}); inlining is version-dependent")
    src = ROOT / "tests" / "data" / "fourbar_regressed.f90"
    missing, total = unvectorised([FORTRAN / "kinds.f90", src], flags, tmp_path)
    assert total == 1
    assert len(missing) == 1 and "exact_block main loop" in missing[0]


BITS_PROGRAM = """program bits
  use kinds, only: dp
  use vecmath, only: sincos_array, atan2_array
  use fourbar, only: exact_states
  use manipulator, only: arm_states
  use ujoint, only: chain_speed, chain_objective
  implicit none
  integer, parameter :: n = 1000
  real(dp) :: x(n), y(n), s(n), c(n), t(n), out(n, 11), qd(n, 2), qdd(n, 2), jac(n, 4), w(n), kap(n)
  real(dp) :: tau(n, 2), l(n), r(n), dr(n), th(n), f, g(5)
  integer :: st(n), k, u
  do k = 1, n
    x(k) = -40.0_dp + 80.0_dp*real(k - 1, dp)/real(n - 1, dp)
    y(k) = 3.0_dp*real(mod(37*k, 101) - 50, dp)/50.0_dp   ! no libm here: its vector variants differ
  end do
  call sincos_array(n, x, s, c)
  call atan2_array(n, y, x, t)
  call exact_states(n, x, 12.0_dp, 5.0_dp, 15.0_dp, 9.0_dp, 5.0_dp, 2.0_dp, 1, out, st)
  qd = 1.5_dp
  qdd = -0.5_dp
  l = 1.0_dp + abs(y)
  call arm_states(n, l, 2.0_dp*l, x, y, qd, qdd, l, l, 9.81_dp, jac, w, kap, tau)
  call chain_speed(2, 3, [0.3_dp, 0.2_dp, 0.25_dp], [1.0_dp, 1.4_dp], [0.1_dp, -0.2_dp], n, x, r, dr, th)
  call chain_objective(2, 0, 3, [0.3_dp, 0.2_dp, 0.25_dp], [1.0_dp, 1.4_dp], [0.1_dp, -0.2_dp], 360, 1, f, g)
  open (newunit=u, file='bits.bin', access='stream', form='unformatted', status='replace')
  write (u) s, c, t, out, st, jac, w, kap, tau, r, dr, th, f, g
  close (u)
end program bits
"""


def test_native_and_portable_builds_give_identical_bits(flags, tmp_path):
    """vecmath's own polynomials (no libmvec) and -ffp-contract=off make the kernels'
    results independent of the instruction set: the same bits from both build flavours.
    (The ujoint kernel before vecmath fails this: gfortran vectorised its cos/sin/atan2
    loops with glibc's libmvec, whose AVX-512 and SSE variants round differently.)"""
    base = [f for f in flags if not f.startswith(("-march=", "-mprefer-vector-width", "-mtune="))]
    blobs = []
    for arch, extra in (("portable", []), ("native", ["-march=native", "-mprefer-vector-width=512"])):
        work = tmp_path / arch
        work.mkdir()
        objs = []
        for src in kernel_sources():
            obj = work / (src.stem + ".o")
            subprocess.run(["gfortran", *base, *extra, "-c", str(src), "-J", str(work), "-o", str(obj)],
                           check=True, capture_output=True, cwd=work)
            objs.append(str(obj))
        (work / "bits.f90").write_text(BITS_PROGRAM)
        subprocess.run(["gfortran", *base, *extra, "-I", str(work), str(work / "bits.f90"), *objs, "-o", "bits"],
                       check=True, capture_output=True, cwd=work)
        subprocess.run([str(work / "bits")], check=True, cwd=work)
        blobs.append((work / "bits.bin").read_bytes())
    assert len(blobs[0]) > 100_000
    assert blobs[0] == blobs[1]


TEMPORARY = re.compile(r"^(?P<file>[^:\s]+\.f90):(?P<line>\d+):\d+:\s*\n(?:.*\n){0,3}?Warning: Creating array temporary",
                       re.MULTILINE)


def test_no_array_temporaries_at_the_summary_kernel_calls(flags, tmp_path):
    """fourbar_summary.f90 hands exact_states (and its speeds_at wrapper) arrays it can use in
    place: no copy-in/out temporary at any call (gfortran -Warray-temporaries; the peak search's
    three exact_states calls made one per call, 11 % of the kernel's time)."""
    work = tmp_path
    calls: dict[int, str] = {}
    for src in kernel_sources():
        res = subprocess.run(["gfortran", *flags, "-Warray-temporaries", "-c", str(src), "-J", str(work), "-I",
                              str(work), "-o", str(work / (src.stem + ".o"))], capture_output=True, text=True, cwd=work)
        assert res.returncode == 0, f"gfortran failed on {src.name}:\n{res.stderr[-3000:]}"
        if src.name != "fourbar_summary.f90":
            continue
        lines = src.read_text().splitlines()
        found = {int(m.group("line")) for m in TEMPORARY.finditer(res.stderr) if Path(m.group("file")).name == src.name}
        calls = {n: lines[n - 1].strip() for n in sorted(found) if re.search(r"\bcall\b", lines[n - 1])}
        assert "Creating array temporary" in res.stderr   # the check sees gfortran's warnings at all
    assert not calls, "array temporaries at calls in fourbar_summary.f90:\n  " + "\n  ".join(
        f"{n}: {t}" for n, t in calls.items())
